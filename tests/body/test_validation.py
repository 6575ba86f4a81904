"""The grown body against published infant data, with the tolerances of docs/validation.md.

WHO medians are boys and girls averaged (body/data/who_*.csv); the newborn's arm is term
newborns' (body/data/newborn_arm.csv). Sources: body/data/README.md.
"""

import math
from importlib import resources

import pytest

from mimo_social.body.builder import build_infant
from mimo_social.body.growth import (YOUNGEST_GROUP, body_measures, circumferences, measurement,
                                     measurements, newborn_arm, segment_factors,
                                     who_arm_circumference, who_head_circumference,
                                     who_medians)
from mimo_social.body.tables import load_body

#: docs/validation.md: relative tolerance of each quantity against its WHO median
LENGTH, WEIGHT, HEAD, ARM = 0.07, 0.10, 0.03, 0.05
WHO_AGES = (0, 6, 12, 18, 24)


@pytest.fixture(scope="module")
def model():
    ages = sorted(set(WHO_AGES) | set(who_head_circumference()) | set(who_arm_circumference()))
    m = body_measures(ages)
    return {a: {k: float(v[i]) for k, v in m.items()} for i, a in enumerate(ages)}


def test_the_newborn_weighs_within_10_percent_of_the_who_median():
    weight = who_medians()[0.0][1]
    for hands in ("mitten", "five_fingers"):
        assert abs(load_body(hands, age_months=0).total_mass / weight - 1) <= 0.10, hands
    compiled = build_infant("mitten", age_months=0).spec.compile()
    mass = compiled.body_subtreemass[compiled.body("hip").id]
    assert mass / weight - 1 == pytest.approx(0.052, abs=0.005)     # 3.46 kg against 3.29


@pytest.mark.parametrize("age", WHO_AGES)
def test_length_and_weight_follow_the_who_medians(model, age):
    length, weight = who_medians()[float(age)]
    assert abs(model[age]["height_cm"] / length - 1) <= LENGTH, model[age]
    assert abs(model[age]["mass_kg"] / weight - 1) <= WEIGHT, model[age]


def test_head_circumference_follows_the_who_medians(model):
    heads = who_head_circumference()
    assert set(heads) == {0.0, 1.0, 6.0, 12.0, 18.0, 24.0}
    for age, ref in heads.items():
        assert abs(model[age]["head_cm"] / ref - 1) <= HEAD, (age, model[age]["head_cm"], ref)


def test_arm_circumference_follows_the_who_medians(model):
    arms = who_arm_circumference()
    assert set(arms) == {3.0, 6.0, 12.0, 18.0, 24.0}               # the standard starts at 3
    for age, ref in arms.items():
        assert abs(model[age]["upper_arm_cm"] / ref - 1) <= ARM, (age, model[age], ref)


def test_the_newborn_arm_matches_term_newborns(model):
    data = newborn_arm()
    arm, head = model[0.0]["upper_arm_cm"], model[0.0]["head_cm"]
    key = "mid_upper_arm_circumference_cm"
    assert abs(arm - data[key]) <= data[key + "_sd"]                 # within 1 SD
    key = "arm_to_head_circumference_ratio"
    assert abs(arm / head - data[key]) <= data[key + "_sd"]


def test_the_circumferences_are_the_geoms():
    t = load_body()
    c = circumferences(t)
    assert c["head"] == pytest.approx(200 * math.pi * 0.0735)
    assert c["upper_arm"] == pytest.approx(200 * math.pi * 0.024)


def test_below_the_youngest_group_the_body_shrinks_isometrically():
    pace = measurement("head_circumference", 0) / measurement("head_circumference", 1)
    for name in measurements():
        assert measurement(name, 0) == pytest.approx(pace * measurement(name, 1), rel=1e-12)
        below = measurement(name, YOUNGEST_GROUP - 1e-9)
        assert below == pytest.approx(measurement(name, YOUNGEST_GROUP), rel=1e-8)  # continuous
    f0, f1 = segment_factors(0), segment_factors(1)
    for seg, (radial, axial, _) in f0.items():
        assert radial == pytest.approx(pace * f1[seg][0], rel=1e-12), seg
        assert axial == pytest.approx(pace * f1[seg][1], rel=1e-12), seg


def test_every_data_file_names_its_source():
    data = resources.files("mimo_social.body").joinpath("data")
    readme = data.joinpath("README.md").read_text()
    for name in ("who_medians.csv", "who_head_circumference.csv", "who_arm_circumference.csv",
                 "newborn_arm.csv", "growth_curves.csv"):
        assert f"`{name}`" in readme, name


def test_the_validation_figure_is_drawn(tmp_path, capsys):
    import numpy as np
    from PIL import Image

    from mimo_social.cli import main

    out = tmp_path / "validation.png"
    assert main(["figure", "validation-body", str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape[0] > 300 and img.shape[1] > 1200
    assert (img.min(axis=2) < 60).mean() > 0.005          # dark text and lines, not blank
