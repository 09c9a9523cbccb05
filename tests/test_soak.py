"""The short soak (tests/soak.py): sim_node at 5× real time, chassis_node, local_nav_node and
planner_node driven by navigation goals, a VFO route, a docking and an undocking in a loop for 4
simulated minutes after 30 s of warm-up (about a minute of wall time). Every goal gets its
result within its allowance, ``/clock`` never stands still, no node dies, and no node's resident
memory grows by more than 15 % (the long soak, 30 simulated minutes, holds it under 5 % and is
run by hand: docs/performance.md).
"""

from __future__ import annotations

import pytest

import soak


@pytest.mark.closed_loop
@pytest.mark.timeout(240)
def test_short_soak_every_goal_ends_nothing_stalls_or_dies(rclpy_context, tmp_path):
    report = soak.run(240.0, tmp_path / "logs", warm_up_s=30.0)
    print(report.text())
    assert not report.stalls and not report.dead, report.text()
    assert report.goals_sent >= 8, report.text()
    assert sum(report.ended.values()) == report.goals_sent, report.text()
    assert all(g < 15.0 for g in report.growth().values()), report.text()
