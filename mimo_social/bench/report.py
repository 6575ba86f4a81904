"""Reading a benchmark report: verdicts (targets, the original MIMo, dense or sparse Jacobian,
scaling, noise, load) and the Markdown text of BENCHMARKS.md."""

from __future__ import annotations

import os

import numpy as np

from .configs import CHUNK, COMPONENTS, CONFIGS, MIMO_REFERENCE, TARGETS, mimo_reference

__all__ = ["by_name", "jacobian_verdict", "scaling_rows", "mimo_comparison", "target_checks",
           "noise_pairs", "noise_note", "load_note", "markdown_table", "scaling_table",
           "build_table", "where_time_goes", "markdown_report"]


def by_name(report) -> dict:
    return {r["name"]: r for r in report["results"]}


def jacobian_verdict(report, tie: float = 0.03) -> list[dict]:
    """Dense against sparse per agent count (only those measured): which is faster, stable?

    The physics time of the two runs is compared chunk by chunk (they ran in turns, next to
    each other in time): ``dense_faster_by`` is the median over chunks of
    ``1 - dense / sparse``; within ``tie`` of 0 there is no clear winner.
    """
    res = by_name(report)
    out = []
    for n in (1, 2, 4, 8):
        dense, sparse = res.get(f"jacobian_dense_{n}"), res.get(f"jacobian_sparse_{n}")
        if not dense or not sparse:
            continue
        d_phy, s_phy = dense["components"]["physics"], sparse["components"]["physics"]
        pairs = [(d, s) for d, s in zip(dense.get("rounds_physics", []),
                                        sparse.get("rounds_physics", [])) if d > 0 and s > 0]
        if pairs:
            rel = float(np.median([1.0 - d / s for d, s in pairs]))
            dense_wins = sum(d < s for d, s in pairs) / len(pairs)
        else:
            rel, dense_wins = 1.0 - d_phy / s_phy, float(d_phy < s_phy)
        winner = "tie" if abs(rel) < tie else ("dense" if rel > 0 else "sparse")
        out.append({"n_agents": n, "dense_total": dense["real_s_per_sim_s"],
                    "sparse_total": sparse["real_s_per_sim_s"],
                    "dense_physics": d_phy, "sparse_physics": s_phy,
                    "dense_faster_by": rel, "dense_faster_in": dense_wins,
                    "chunks": len(pairs), "winner": winner,
                    "dense_unstable": dense["unstable_episodes"],
                    "sparse_unstable": sparse["unstable_episodes"],
                    "dense_episodes": dense["episodes"], "sparse_episodes": sparse["episodes"]})
    return out


def scaling_rows(report) -> list[dict]:
    """Per agent count of ``agents_N``: total, per infant, and per infant relative to one."""
    res = by_name(report)
    rows = [res[f"agents_{n}"] for n in (1, 2, 4, 8) if f"agents_{n}" in res]
    one = res.get("agents_1")
    out = []
    for r in rows:
        n = r["n_agents"]
        per = r["real_s_per_sim_s"] / n
        blind = (r["real_s_per_sim_s"] - r["components"]["vision"]) / n
        one_blind = (one["real_s_per_sim_s"] - one["components"]["vision"]) if one else None
        out.append({"name": r["name"], "n_agents": n, "total": r["real_s_per_sim_s"],
                    "per_agent": per,
                    "relative": per / one["real_s_per_sim_s"] if one else None,
                    "relative_without_vision": blind / one_blind if one_blind else None,
                    "per_agent_components": {k: r["components"].get(k, 0.0) / n
                                             for k in COMPONENTS}})
    return out


def mimo_comparison(report) -> list[dict]:
    """Per result: the published MIMo figure it is compared with and whether it is ahead."""
    out = []
    for r in report["results"]:
        ref = r.get("mimo_reference", mimo_reference(r))
        if not ref:
            continue
        total = r["real_s_per_sim_s"]
        out.append({"name": r["name"], "total": total, "reference": ref["value"],
                    "label": ref["label"], "factor": ref["value"] / total,
                    "ahead": total < ref["value"]})
    return out


def target_checks(report) -> list[dict]:
    """The package's speed targets, each with the measured value and whether it is met."""
    res = by_name(report)
    out = []
    if "default" in res:
        r = res["default"]
        total = r["real_s_per_sim_s"]
        env_only = total - r["components"]["recording"]
        out.append({"target": "default configuration (2 x 256² eyes, touch x1, recorded) "
                              f"< {TARGETS['default_max']} real s / sim s",
                    "measured": f"{total:.3f} ({1 / total:.1f}x real time); "
                                f"{env_only:.3f} without the recording",
                    "met": total < TARGETS["default_max"],
                    "met_without_recording": env_only < TARGETS["default_max"]})
    comp = mimo_comparison(report)
    if comp:
        behind = [c for c in comp if not c["ahead"]]
        worst = min(comp, key=lambda c: c["factor"])
        out.append({"target": "every configuration ahead of the original MIMo on this machine",
                    "measured": (f"{len(comp) - len(behind)} of {len(comp)} ahead; least: "
                                 f"`{worst['name']}` {worst['factor']:.1f}x faster than MIMo "
                                 f"{worst['label']} ({worst['reference']:g})"
                                 + (("; behind: " + ", ".join(f"`{c['name']}`" for c in behind))
                                    if behind else "")),
                    "met": not behind})
    colds = [(r["name"], r["build_cold_s"] + (r["fresh_process"]["cold"].get("first_reset_s")
                                              or 0.0))
             for r in report["results"] if r.get("build_cold_s") is not None]
    if colds:
        name, worst = max(colds, key=lambda x: x[1])
        out.append({"target": "building with touch (fresh process, empty skin cache, build + "
                              f"first reset) faster than the original MIMo's "
                              f"~{MIMO_REFERENCE['build_with_touch_s']:.0f} s",
                    "measured": f"at most {worst:.2f} s (`{name}`)",
                    "met": worst < MIMO_REFERENCE["build_with_touch_s"]})
    if "basic_1" in res:  # the whole step of an infant with exactly these senses
        total = res["basic_1"]["real_s_per_sim_s"]
        out.append({"target": "one infant (physics + proprioception + vestibular) "
                              f"<= {TARGETS['agents_1_max']} real s / sim s",
                    "measured": f"{total:.4f} (the whole step of `basic_1`)",
                    "met": total <= TARGETS["agents_1_max"]})
    elif "agents_1" in res:
        r = res["agents_1"]
        c = r["components"]
        pps = c["physics"] + c["proprioception"] + c["vestibular"]
        out.append({"target": "one infant (physics + proprioception + vestibular) "
                              f"<= {TARGETS['agents_1_max']} real s / sim s",
                    "measured": f"{pps:.4f} (those three components of `agents_1`, which also "
                                "renders and feels: add `basic_1` for the exact figure)",
                    "met": pps <= TARGETS["agents_1_max"]})
    builds = []
    cold = report.get("cold_start") or {}
    if "build_2_agents_s" in cold:
        builds.append(("fresh process", cold["build_2_agents_s"]))
    if "agents_2" in res:
        builds.append(("`agents_2` in the benchmark process", res["agents_2"]["build_s"]))
    if builds:
        worst = max(b for _, b in builds)
        out.append({"target": f"building a 2-infant env < {TARGETS['build_2_agents_max_s']} s",
                    "measured": "; ".join(f"{b:.3f} s {where}" for where, b in builds),
                    "met": worst < TARGETS["build_2_agents_max_s"]})
    grow = [s for s in scaling_rows(report) if s["n_agents"] > 1 and s["relative"] is not None]
    if grow:
        lim = TARGETS["scaling_per_infant_max"]
        out.append({"target": f"scaling close to linear: N infants <= {lim} x N x one infant",
                    "measured": "; ".join(f"{s['n_agents']} infants {s['relative']:.2f}x one "
                                          "per infant" for s in grow)
                                + " (all but vision: " + "; ".join(
                                    f"{s['relative_without_vision']:.2f}x" for s in grow)
                                + ")",
                    "met": all(s["relative"] <= lim for s in grow)})
    return out


def noise_pairs(report) -> list[tuple[str, str]]:
    """Pairs of measured configurations that are the same run (same env, same actions)."""
    keys: dict[str, list[str]] = {}
    for r in report["results"]:
        cfg = CONFIGS.get(r["name"])
        if cfg is not None:
            keys.setdefault(cfg.key(), []).append(r["name"])
    return [(names[0], other) for names in keys.values() if len(names) > 1
            for other in names[1:]]


def noise_note(report) -> str:
    """A sentence on the run's noise, from configurations that are the same run."""
    res = by_name(report)
    parts = []
    for a, b in noise_pairs(report):
        x, y = res[a]["real_s_per_sim_s"], res[b]["real_s_per_sim_s"]
        parts.append(f"`{a}` and `{b}` (totals {x:.4f} and {y:.4f}: "
                     f"{abs(x - y) / min(x, y) * 100:.0f} % apart)")
    if not parts:
        return ""
    return ("Noise check: " + "; ".join(parts) + " are the same configuration (same env, same "
            "actions, same trajectory), measured side by side; their difference is the "
            "measurement noise of this run, and differences of that size between other rows "
            "mean nothing.")


def load_note(report) -> str:
    """Whether other work shared the machine during the run (load averages)."""
    st, mach = report["settings"], report["machine"]
    before, during = st.get("load_average_before"), st.get("load_1min_during")
    cores = mach.get("usable_cores") or mach.get("cores") or 1
    if not before:
        return ""
    text = (f"Load average (1, 5, 15 min) before the run: {before}; 1-min load during the "
            + (f"run: mean {during['mean']}, max {during['max']}" if during else "run: unknown")
            + f" (the benchmark itself adds about 1, more while Mesa renders; {cores} cores).")
    busy_before = before[0] >= 0.5 * cores or (len(before) > 1 and before[1] >= 0.5 * cores)
    busy_during = during is not None and during["mean"] >= cores + 0.5
    if busy_before or busy_during:
        text = ("**The machine was shared with other jobs during this run** (the load was high), "
                "so every figure is somewhat pessimistic; the configurations ran in "
                f"interleaved turns of {CHUNK} steps, so they were slowed alike. " + text)
    return text


# -- Markdown --------------------------------------------------------------------------------
def _f(x: float) -> str:
    return f"{x:.4f}"


def _ahead(r) -> str:
    ref = r.get("mimo_reference")
    if not ref:
        return "-"
    k = ref["value"] / r["real_s_per_sim_s"]
    word = "ahead" if k > 1 else "**behind**"
    return f"{ref['value']:g} ({ref['label']}): {word}, {k:.1f}x"


def markdown_table(report) -> str:
    head = ("| configuration | agents | real s / sim s | × real time | "
            + " | ".join(COMPONENTS)
            + " | CPU s / sim s | build s | episodes (unstable) | original MIMo here |")
    lines = [head, "|" + "---|" * (len(COMPONENTS) + 8)]
    for r in report["results"]:
        c = r["components"]
        lines.append(
            f"| `{r['name']}` | {r['n_agents']} | **{_f(r['real_s_per_sim_s'])}** "
            f"| {1.0 / r['real_s_per_sim_s']:.1f} "
            + "".join(f"| {_f(c.get(k, 0.0))} " for k in COMPONENTS)
            + f"| {_f(r['cpu_s_per_sim_s'])} | {r['build_s']:.3f} "
            f"| {r['episodes']} ({r['unstable_episodes']}) | {_ahead(r)} |")
    return "\n".join(lines)


def _descriptions(report) -> str:
    return "\n".join(f"- `{r['name']}`: {r.get('description', '')}" for r in report["results"])


def scaling_table(report) -> str:
    rows = scaling_rows(report)
    if not rows:
        return ""
    parts = ("physics", "touch", "vision", "recording")
    lines = ["| infants | real s / sim s | per infant | per infant, relative to 1 infant | "
             "all but vision, per infant, relative to 1 infant | "
             + " | ".join(f"{p} per infant" for p in parts) + " | build s |",
             "|" + "---|" * (6 + len(parts))]
    res = by_name(report)
    for s in rows:
        rel = f"{s['relative']:.2f}" if s["relative"] is not None else "-"
        blind = (f"{s['relative_without_vision']:.2f}"
                 if s["relative_without_vision"] is not None else "-")
        lines.append(f"| {s['n_agents']} | {_f(s['total'])} | {_f(s['per_agent'])} | {rel} | "
                     f"{blind} | "
                     + " | ".join(_f(s["per_agent_components"][p]) for p in parts)
                     + f" | {res[s['name']]['build_s']:.3f} |")
    return "\n".join(lines)


def build_table(report) -> str:
    rows = [r for r in report["results"] if r.get("fresh_process")]
    if not rows:
        return ""
    lines = ["| configuration | in this process (skin cached) | fresh process, empty skin "
             "cache: import / build / first reset | fresh process, warm skin cache: import / "
             "build / first reset |", "|---|---|---|---|"]

    def cell(f):
        if "error" in f:
            return f"failed: {f['error']}"
        return (f"{f['import_s']:.2f} / **{f['build_s']:.2f}** / {f['first_reset_s']:.2f} s "
                f"(skin: {', '.join(f.get('skin') or []) or '-'})")

    for r in rows:
        f = r["fresh_process"]
        lines.append(f"| `{r['name']}` | {r['build_s']:.3f} s | {cell(f['cold'])} | "
                     f"{cell(f['warm'])} |")
    return "\n".join(lines)


def where_time_goes(report) -> str:
    """Data-driven remarks: what dominates, what grows, where the recording and tasks cost."""
    res = by_name(report)
    parts = []
    for name in ("default", "agents_1"):
        if name in res:
            r = res[name]
            tot = r["real_s_per_sim_s"]
            shares = sorted(r["components"].items(), key=lambda kv: -kv[1])
            parts.append(f"in `{name}` ({tot:.3f} real s / sim s) the time goes to "
                         + ", ".join(f"{k} {v / tot * 100:.0f} % ({v:.3f})"
                                     for k, v in shares if v / tot >= 0.01))
            break
    recs = [(r["name"], r["components"]["recording"], r["real_s_per_sim_s"])
            for r in report["results"] if r["components"].get("recording", 0) > 0]
    if recs:
        hi = max(recs, key=lambda x: x[1] / x[2])
        lo = min(recs, key=lambda x: x[1] / x[2])
        text = (f"recording (the Rerun recorder with its defaults) costs from "
                f"{lo[1] / lo[2] * 100:.0f} % (`{lo[0]}`) to {hi[1] / hi[2] * 100:.0f} % "
                f"(`{hi[0]}`, {hi[1]:.3f} real s / sim s) of a run")
        sizes = [(r["name"], r["recording"]["mb_per_sim_min"]) for r in report["results"]
                 if (r.get("recording") or {}).get("mb_per_sim_min")]
        if sizes:
            big = max(sizes, key=lambda x: x[1])
            small = min(sizes, key=lambda x: x[1])
            text += (f"; its files take {small[1]:.0f} (`{small[0]}`) to {big[1]:.0f} MB "
                     f"(`{big[0]}`) per simulated minute")
        parts.append(text)
    sweep = [res[n] for n in ("v64", "v128", "default", "v512") if n in res]
    if len(sweep) > 1:
        a, b = sweep[0], sweep[-1]
        px = (b["senses"]["vision"][0] * b["senses"]["vision"][1]
              / (a["senses"]["vision"][0] * a["senses"]["vision"][1]))
        parts.append("vision costs " + " / ".join(f"{r['components']['vision']:.3f}"
                                                  for r in sweep)
                     + " at " + " / ".join(f"{r['senses']['vision'][0]}²" for r in sweep)
                     + f": {px:.0f}x the pixels cost "
                     f"{b['components']['vision'] / a['components']['vision']:.1f}x the time "
                     "(a fixed cost per frame dominates the small images)")
    sweep = [res[n] for n in ("t0.25", "t0.5", "default", "t2") if n in res]
    if len(sweep) > 1 and all(r.get("touch_points") for r in sweep):
        a, b = sweep[0], sweep[-1]
        parts.append("touch costs " + " / ".join(f"{r['components']['touch']:.3f}"
                                                 for r in sweep)
                     + " at x" + " / x".join(f"{r['senses']['touch']:g}" for r in sweep)
                     + " (" + " / ".join(str(r["touch_points"]) for r in sweep)
                     + f" skin points): {b['touch_points'] / a['touch_points']:.1f}x the points "
                     f"cost {b['components']['touch'] / a['components']['touch']:.2f}x the "
                     "time (the work is per contact, not per skin point)")
    if "default" in res and "five_fingers" in res:
        d, f = res["default"]["components"], res["five_fingers"]["components"]
        ratio = res["five_fingers"]["real_s_per_sim_s"] / res["default"]["real_s_per_sim_s"]
        parts.append(f"five-fingered hands cost {ratio:.1f}x "
                     f"the mitten default (physics {f['physics'] / d['physics']:.1f}x, vision "
                     f"{f['vision'] / max(d['vision'], 1e-12):.1f}x, touch "
                     f"{f['touch'] / max(d['touch'], 1e-12):.1f}x)")
    if "default" in res and "muscle" in res:
        d, m = res["default"]["components"], res["muscle"]["components"]
        ratio = res["muscle"]["real_s_per_sim_s"] / res["default"]["real_s_per_sim_s"]
        parts.append(f"muscles cost {ratio:.2f}x "
                     f"the spring-damper default: {m['physics'] / d['physics']:.2f}x its "
                     "physics (the muscle dynamics run before every physics sub-step, so "
                     "their time counts as `physics`) and "
                     f"{m['actuation'] / max(d['actuation'], 1e-12):.2f}x its actuation")
    sc = scaling_rows(report)
    if len(sc) > 1 and sc[0]["n_agents"] == 1:
        a, b = sc[0], sc[-1]
        grow = {k: b["per_agent_components"][k] / a["per_agent_components"][k]
                for k in COMPONENTS if a["per_agent_components"][k] > 1e-5}
        worst = max(grow, key=lambda k: b["per_agent_components"][k]
                    - a["per_agent_components"][k])
        parts.append(f"from 1 to {b['n_agents']} infants the cost per infant grows "
                     f"{b['per_agent'] / a['per_agent']:.2f}x; most of the growth is {worst} "
                     f"({grow[worst]:.2f}x per infant: "
                     + ("each eye sees the other infants, so the rendering work per infant "
                        "grows with their number" if worst == "vision" else
                        "more bodies in one world") + ")"
                     + "; per component: " + ", ".join(f"{k} {v:.2f}x" for k, v in grow.items()))
    slow = [r for r in report["results"]
            if r["components"]["task"] > r["components"]["physics"] > 0]
    for r in slow:
        parts.append(f"in `{r['name']}` the task's own per-step work (`task`) takes "
                     f"{r['components']['task']:.4f} real s / sim s, "
                     f"{r['components']['task'] / r['components']['physics']:.1f}x the physics")
    if not parts:
        return ""
    return "\n".join(f"- {p[0].upper() + p[1:]}." for p in parts)


def _mimo_paragraph(report) -> str:
    comp = mimo_comparison(report)
    if not comp:
        return ""
    ref = MIMO_REFERENCE
    lines = [f"The original MIMo, measured on this machine: default configuration (one infant, "
             f"2 x 256² eyes, touch x1, two objects) ~{ref['default']:g} real s per simulated s, "
             f"without vision {ref['without_vision']:g}, physics alone {ref['physics_only']:g}; "
             f"~{ref['build_with_touch_s']:.0f} s to build with touch "
             f"(~{ref['build_without_touch_s']:.0f} s without). Each configuration is compared "
             "with the closest of these figures (anything with eyes with the default, whatever "
             "its image size; multi-infant worlds as a whole with one original infant):", ""]
    for c in comp:
        lines.append(f"- `{c['name']}`: {c['total']:.4f} against {c['reference']:g} "
                     f"({c['label']}): " + (f"ahead, {c['factor']:.1f}x faster" if c["ahead"]
                                            else f"**behind**, {1 / c['factor']:.1f}x slower"))
    colds = [(r["name"], r["build_cold_s"]) for r in report["results"]
             if r.get("build_cold_s") is not None]
    if colds:
        lo, hi = min(colds, key=lambda x: x[1]), max(colds, key=lambda x: x[1])
        lines.append(f"- building with touch in a fresh process with an empty skin cache takes "
                     f"{lo[1]:.2f} s (`{lo[0]}`) to {hi[1]:.2f} s (`{hi[0]}`), against "
                     f"~{ref['build_with_touch_s']:.0f} s for the original MIMo")
    return "\n".join(lines)


def _plot_links(plot) -> list[str]:
    if not plot:
        return []
    return [plot] if isinstance(plot, (str, os.PathLike)) else list(plot)


def markdown_report(report, command: str | None = None, plot=None) -> str:
    """The whole BENCHMARKS.md text: machine, command, tables, plots, targets, MIMo, Jacobian.
    ``plot``: the path (or list of paths) of the charts, relative to the Markdown file."""
    mach = report["machine"]
    st = report["settings"]
    out = ["# Benchmarks", "",
           "Real (wall-clock) seconds per simulated second, split by component, for each "
           "configuration; smaller is faster, and `× real time` is its inverse. The grid is the "
           "MIMo paper's (its Sec. VI-B, Fig. 6): one infant with mitten hands and spring-damper "
           "actuation, two free objects, random actions, every sense, vision at "
           "{64, 128, 256, 512}² with touch x1 and touch at x{0.25, 0.5, 1, 2} the published "
           "point density with vision at 256², episodes of one simulated minute; every run is "
           "recorded to a Rerun file (`mimo_social.recording.recorder.Recorder` with its defaults). "
           "Every configuration runs the same smooth random actions (low-pass filtered "
           "uniform noise per motor, seeded, mapped onto each action space's bounds), generated "
           "before the timed loop. The components come from `env.timing` (inside `env.step`) "
           "and the recorder's calls; `other` is the Python overhead around them (dict building "
           "in `step`, the call, the loop), so they sum to the total. `physics_only` is the "
           "floor: the grid's scene stepped by a bare `mujoco.mj_step` loop. All envs are built "
           "first (`build s`, in this process, skin from the cache), then the configurations "
           f"run in turns of {CHUNK} control steps, so a change in the machine's speed during "
           "the run touches them alike; resets between episodes are not counted. The count in "
           "brackets is of episodes that ended unstable. `CPU s / sim s` is the process's CPU "
           "time, Mesa's rasterizer threads included (so it can exceed the real time with "
           "vision); clearly below the real time, it means the benchmark waited for a CPU.", "",
           "## Machine", "",
           f"- CPU: {mach['cpu']} ({mach['cores']} cores"
           + (f", {mach['usable_cores']} usable"
              if mach.get("usable_cores") != mach["cores"] else "")
           + (f", {mach['cpu_mhz']:.0f} MHz" if mach.get("cpu_mhz") else "")
           + (f"), {mach['memory_gb']} GB RAM" if mach.get("memory_gb") else ")"),
           f"- MuJoCo {mach['mujoco']}, NumPy {mach['numpy']}, Python {mach['python']}, "
           f"{mach['platform']}",
           f"- OpenGL: MUJOCO_GL={mach['mujoco_gl']}"
           + (f", {mach['gl_renderer']}" if mach.get("gl_renderer") else "")
           + (f", LP_NUM_THREADS={mach['lp_num_threads']}" if mach.get("lp_num_threads") else
              " (no GPU: Mesa software rendering)"),
           f"- measured {st['date_utc']} UTC, {st['sim_seconds']:g} simulated s per "
           f"configuration, seed {st['seed']}"
           + (f", {st['wall_s'] / 60:.1f} min in all" if st.get("wall_s") else ""), ""]
    load = load_note(report)
    if load:
        out += [load, ""]
    if command:
        out += ["Produced by:", "", "```", command, "```", ""]
    out += ["## Results", "", markdown_table(report), ""]
    noise = noise_note(report)
    if noise:
        out += [noise, ""]
    skipped = report.get("skipped") or []
    if skipped:
        out += ["Skipped (could not be built or run):", ""]
        out += [f"- `{s['name']}` ({s.get('stage', 'build')}): {s['reason']}" for s in skipped]
        out.append("")
    recfail = [r for r in report["results"] if (r.get("recording") or {}).get("error")]
    if recfail:
        out += ["Recorder failures (those runs went on unrecorded from that point):", ""]
        out += [f"- `{r['name']}`: {r['recording']['error']}" for r in recfail]
        out.append("")
    out += ["Configurations:", "", _descriptions(report), ""]
    links = _plot_links(plot)
    captions = ["The paper's grid (like its Fig. 6): real s per simulated s, stacked by component",
                "Tasks, bodies and infants in one world (like the paper's Fig. 7), stacked by "
                "component"]
    for i, p in enumerate(links):
        cap = captions[i] if len(links) > 1 and i < len(captions) else \
            "Real seconds per simulated second, stacked by component"
        out += [f"![{cap}]({p})", ""]
    sc = scaling_table(report)
    if sc:
        out += ["## Infants in one world", "", "Every sense (vision 64², touch x1), two objects, "
                "recorded; the total for the whole world and per infant.", "", sc, ""]
    bt = build_table(report)
    if bt:
        out += ["## Build time", "",
                "Every configuration with touch, built in a fresh Python process (after its "
                "imports), first with `MIMO_SOCIAL_CACHE` pointing at a new empty directory "
                "(the skin is computed), then again with the cache that run filled (the skin is "
                "read from disk); the first reset makes the GL context of the eyes.", "", bt, ""]
    checks = target_checks(report)
    if checks:
        out += ["## Targets", "", "| target | measured | met |", "|---|---|---|"]
        for c in checks:
            out.append(f"| {c['target']} | {c['measured']} | {'yes' if c['met'] else '**no**'} |")
        out.append("")
    where = where_time_goes(report)
    if where:
        out += ["## Where the time goes", "", where, ""]
    para = _mimo_paragraph(report)
    if para:
        out += ["## Compared with the original MIMo", "", para, ""]
    verdicts = jacobian_verdict(report)
    if verdicts:
        out += ["## Jacobian: dense or sparse", ""]
        for v in verdicts:
            stab = (f"dense {v['dense_unstable']}/{v['dense_episodes']} and sparse "
                    f"{v['sparse_unstable']}/{v['sparse_episodes']} episodes unstable")
            if v["winner"] == "tie":
                verdict = "no clear winner (the median chunk differs by less than 3 %)"
            else:
                wins = v["dense_faster_in"] if v["winner"] == "dense" else 1 - v["dense_faster_in"]
                verdict = (f"**{v['winner']} is faster**: its physics takes "
                           f"{abs(v['dense_faster_by']) * 100:.0f} % less time in the median "
                           f"chunk, and less in {wins * 100:.0f} % of the {v['chunks']} chunks")
            out.append(f"- {v['n_agents']} infant{'s' if v['n_agents'] > 1 else ''}: physics "
                       f"{_f(v['dense_physics'])} (dense) vs {_f(v['sparse_physics'])} (sparse) "
                       f"real s / sim s, totals {_f(v['dense_total'])} vs {_f(v['sparse_total'])}: "
                       f"{verdict}; {stab}.")
        out.append("")
    return "\n".join(out)
