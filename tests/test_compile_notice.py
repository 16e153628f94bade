"""The line on stderr while the first step compiles (issue 36): a first step that has not finished
within a second says it is compiling; a quick one, and every later step, say nothing."""

from __future__ import annotations

import time

import framework.scene as scene_module
from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.compile_notice import FIRST_STEP_NOTICE, notice_if_slow


def _scene(pause: float) -> Scene:
    s = Scene(gravity=(0.0, -10.0))
    s.spawn(Transform(0.0, 0.0), Hitbox(AABB(1.0, 1.0)), Velocity(0.0, 0.0))
    s.add_system(lambda scene, dt: time.sleep(pause))  # as numba compiling the kernels would
    return s


def test_a_slow_first_step_says_it_is_compiling_once(monkeypatch, capsys):
    monkeypatch.setattr(scene_module, "_STEPPED", False)
    s = _scene(1.3)
    s.step(1 / 60)
    assert capsys.readouterr().err.strip() == FIRST_STEP_NOTICE
    s.step(1 / 60)  # as slow, but not the first: it has compiled
    assert capsys.readouterr().err == ""


def test_a_quick_first_step_says_nothing(monkeypatch, capsys):
    monkeypatch.setattr(scene_module, "_STEPPED", False)
    _scene(0.0).step(1 / 60)
    time.sleep(1.2)  # (the notice's timer was cancelled: nothing comes later either)
    assert capsys.readouterr().err == ""


def test_the_notice_is_said_only_while_the_block_runs(capsys):
    with notice_if_slow("slow", after=0.2):
        time.sleep(0.5)
    assert capsys.readouterr().err == "slow\n"
    with notice_if_slow("quick", after=0.2):
        pass
    time.sleep(0.4)
    assert capsys.readouterr().err == ""
