"""scripts/joint_attention_checking_follower.py: the scripted follower and each checking setting
played on the same seeds, a line each with the success rate and the share on target."""

from __future__ import annotations

import re


def test_it_prints_a_line_per_setting_with_the_success_rate(load_script, capsys):
    script = load_script("joint_attention_checking_follower")
    assert script.main(["--episodes", "1", "--look-s", "2", "--peripheral", "0", "3"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert [line.split(":")[0] for line in lines] == ["scripted follower"] + ["checking"] * 2
    assert "peripheral 0 deg" in lines[1] and "peripheral 3 deg" in lines[2]
    rates = [int(re.search(r"success (\d+)% of 1,", line).group(1)) for line in lines]
    assert rates[0] == 100 and rates[2] == 100           # seed 1000: both succeed
