"""Bodies that grow: the infant's segments at an age from 0 to 33 months, from growth curves.

Data (``body/data``, sources in ``body/data/README.md``):

- ``growth_curves.csv``: 16 body measurements (cm) as functions of age,
  ``measurement(age) = a ln(age + b) + c`` (the means of the AnthroKids 1977 infant survey as
  fitted by the MIMo v2 authors, 2025);
- ``growth_map.csv``: which measurement sets each segment's size across (``radial``) and along
  (``axial``, on its ``long_axis``): a measurement name, ``A - B`` (a difference of two
  measurements, e.g. the forearm: elbow-hand length minus hand length) or ``A & B`` (the
  geometric mean of both factors, e.g. the shank's calf and ankle).

A segment's factor at an age is ``measurement(age) / measurement(18)``: the 18-month body is the
published one (every factor exactly 1, the tables bit for bit) and every other age keeps its
hand-tuned proportions.

Below the survey's youngest group (mean age 1 month, :data:`YOUNGEST_GROUP`) the curves have no
data, and three of them cannot be extrapolated: the fits of upper-arm and forearm circumference
stopped at ``b`` = 0.1 to 15 digits (a bound of the fit) and hip breadth's at 0.105, so they
fall without limit towards -0.1 months. At birth they made the trunk (half the body's mass; hip
breadth sets it both ways) 0.57 of its 18-month size, volume 0.18, where the other curves keep
0.63-0.76 of theirs: the newborn came out 2.81 kg, 15 % under the WHO median. Below 1 month
every measurement is therefore its 1-month value times ``head_circumference(age) /
head_circumference(1)``: the body keeps the proportions of the youngest measured group and
grows isometrically, as the WHO medians say infants do in their first month (length x1.095,
head circumference x1.080, weight x1.316 = 1.095^3.04), at the pace of the one curve whose newborn
value a standard checks (head circumference at birth 34.44 cm; WHO median 34.17 cm).
``body/data/README.md`` and ``docs/validation.md`` give the figures.

:func:`grow_body` applies the factors with :func:`~mimo_social.body.resize.resize_body` (masses
at constant density, torques and passive joint parameters with the volume of the part a joint
moves; see there).
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import replace
from importlib import resources

from .resize import resize_body
from .tables import AGE_RANGE, BodyTables, load_body

__all__ = ["AGE_RANGE", "REFERENCE_AGE", "YOUNGEST_GROUP", "measurement", "measurements",
           "segment_factors", "grow_body", "who_medians", "who_head_circumference",
           "who_arm_circumference", "newborn_arm", "circumferences", "body_measures",
           "growth_table"]

#: The age of the published body: every factor is 1 there.
REFERENCE_AGE = 18.0
#: The mean age (months) of the survey's youngest group: below it the body grows isometrically.
YOUNGEST_GROUP = 1.0
#: The measurement that paces growth below YOUNGEST_GROUP.
_PACE = "head_circumference"


def _rows(filename: str) -> list[dict]:
    with resources.files("mimo_social.body").joinpath("data", filename).open() as f:
        return list(csv.DictReader(f))


@functools.lru_cache(maxsize=None)
def _curves() -> dict:
    return {r["measurement"]: (float(r["a"]), float(r["b"]), float(r["c"]))
            for r in _rows("growth_curves.csv")}


@functools.lru_cache(maxsize=None)
def _map() -> dict:
    return {r["segment"]: (r["radial"].strip(), r["axial"].strip(), r["long_axis"].strip() or "z")
            for r in _rows("growth_map.csv")}


def measurements() -> tuple[str, ...]:
    """The names of the measurements in ``growth_curves.csv``."""
    return tuple(_curves())


def _age(age_months) -> float:
    age = float(age_months)
    if not AGE_RANGE[0] <= age <= AGE_RANGE[1]:  # NaN fails too
        raise ValueError(f"age_months={age_months!r} is out of range; allowed: "
                         f"{AGE_RANGE[0]:g} to {AGE_RANGE[1]:g}")
    return age


def _curve(name: str, age: float) -> float:
    a, b, c = _curves()[name]
    return a * math.log(age + b) + c


def measurement(name: str, age_months: float) -> float:
    """The measurement ``name`` (cm) at ``age_months``: ``a ln(age + b) + c`` from the
    youngest group (1 month) on; below it the 1-month value times the head circumference's
    ratio to its own 1-month value (isometric growth; see the module docstring)."""
    if name not in _curves():
        raise ValueError(f"unknown growth measurement {name!r}; known: {sorted(_curves())}")
    age = _age(age_months)
    if age >= YOUNGEST_GROUP:
        return _curve(name, age)
    pace = _curve(_PACE, age) / _curve(_PACE, YOUNGEST_GROUP)
    return _curve(name, YOUNGEST_GROUP) * pace


def _factor(expr: str, age: float) -> float:
    """The factor of one growth_map entry at ``age`` relative to REFERENCE_AGE."""
    if "&" in expr:
        parts = [_factor(p.strip(), age) for p in expr.split("&")]
        return math.prod(parts) ** (1.0 / len(parts))
    names = [p.strip() for p in expr.split(" - ")]

    def value(at):
        return measurement(names[0], at) - sum(measurement(n, at) for n in names[1:])

    return value(age) / value(REFERENCE_AGE)


@functools.lru_cache(maxsize=None)
def _segment_factors(age: float) -> dict:
    return {seg: (_factor(r, age), _factor(a, age), axis)
            for seg, (r, a, axis) in _map().items()}


def segment_factors(age_months: float, segments=None) -> dict:
    """Segment name -> ``(radial, axial, long_axis)`` at ``age_months`` (right side and
    midline; :func:`~mimo_social.body.resize.resize_body` gives a left segment its right
    twin's factors). ``segments``: keep only these names (those of one hand version)."""
    factors = _segment_factors(_age(age_months))
    if segments is None:
        return dict(factors)
    return {k: v for k, v in factors.items() if k in set(segments)}


def grow_body(tables: BodyTables, age_months: float) -> BodyTables:
    """The 18-month ``tables`` grown (or shrunk) to ``age_months``; the result records the age.
    Every segment of the tables must be in ``growth_map.csv`` (its left twin through its right
    one)."""
    names = [s.name for s in tables.segments]
    factors = segment_factors(age_months, names)
    missing = [n for n in names if n not in factors
               and not (n.startswith("left_") and "right_" + n[5:] in factors)]
    if missing:
        raise ValueError(f"growth_map.csv has no row for segments {missing}")
    grown = resize_body(tables, factors)
    return replace(grown, age_months=float(age_months))


@functools.lru_cache(maxsize=None)
def who_medians() -> dict:
    """WHO Child Growth Standards medians, boys and girls averaged: age (months) ->
    ``(length_cm, weight_kg)`` (``who_medians.csv``; sources in ``body/data/README.md``)."""
    out = {}
    for r in _rows("who_medians.csv"):
        length = (float(r["length_boys_cm"]) + float(r["length_girls_cm"])) / 2
        weight = (float(r["weight_boys_kg"]) + float(r["weight_girls_kg"])) / 2
        out[float(r["age_months"])] = (length, weight)
    return out


@functools.lru_cache(maxsize=None)
def who_head_circumference() -> dict:
    """WHO Child Growth Standards head-circumference-for-age medians, boys and girls averaged:
    age (months) -> cm (``who_head_circumference.csv``; sources in ``body/data/README.md``)."""
    return {float(r["age_months"]): (float(r["head_boys_cm"]) + float(r["head_girls_cm"])) / 2
            for r in _rows("who_head_circumference.csv")}


@functools.lru_cache(maxsize=None)
def who_arm_circumference() -> dict:
    """WHO Child Growth Standards arm-circumference-for-age medians (3 to 24 months), boys and
    girls averaged: age (months) -> cm (``who_arm_circumference.csv``)."""
    return {float(r["age_months"]): (float(r["arm_boys_cm"]) + float(r["arm_girls_cm"])) / 2
            for r in _rows("who_arm_circumference.csv")}


@functools.lru_cache(maxsize=None)
def newborn_arm() -> dict:
    """Term newborns' mid-upper-arm circumference (cm) and arm-to-head circumference ratio:
    quantity -> mean, and quantity + ``"_sd"`` -> its SD (``newborn_arm.csv``)."""
    out = {}
    for r in _rows("newborn_arm.csv"):
        out[r["quantity"]] = float(r["value"])
        out[r["quantity"] + "_sd"] = float(r["sd"])
    return out


def circumferences(tables: BodyTables) -> dict:
    """The body's head and mid-upper-arm circumferences (cm): ``2 pi r`` of the head sphere
    and of the right upper arm's capsule."""
    radius = {g.name: g.size[0] for g in tables.geoms}
    return {"head": 200 * math.pi * radius["head"],
            "upper_arm": 200 * math.pi * radius["right_upper_arm"]}


def growth_table(hands: str = "mitten") -> list[tuple]:
    """Rows ``(age, height_cm, mass_kg, who_length_cm, who_weight_kg)`` for the ages of
    ``who_medians.csv``: the grown body's standing height (head top to soles, every joint at 0)
    and mass beside the WHO medians (docs/bodies.md prints it)."""
    rows = []
    for age, (length, weight) in who_medians().items():
        t = load_body(hands, age_months=age)
        rows.append((age, 100 * t.standing_height, t.total_mass, length, weight))
    return rows


def body_measures(ages, hands: str = "mitten") -> dict:
    """The grown body at each of ``ages`` (months): arrays ``age``, ``height_cm`` (standing,
    head top to soles), ``mass_kg``, ``head_cm`` and ``upper_arm_cm`` (circumferences)."""
    import numpy as np

    rows = []
    for age in ages:
        t = load_body(hands, age_months=float(age))
        c = circumferences(t)
        rows.append((float(age), 100 * t.standing_height, t.total_mass, c["head"],
                     c["upper_arm"]))
    cols = np.array(rows, float).reshape(-1, 5).T
    return dict(zip(("age", "height_cm", "mass_kg", "head_cm", "upper_arm_cm"), cols))
