"""The level-test sweep (``python -m examples.platformer.sweep``; the rl extra)."""

from __future__ import annotations

import importlib.util
import json
import sys

import pytest

pytest.importorskip("gymnasium", reason="the rl extra (gymnasium) is not installed: pip install -e '.[rl]'")

from examples.platformer import sweep  # noqa: E402


def test_tasks_play_the_scripted_agent_once_and_the_random_one_per_seed():
    tasks = sweep.tasks_for([0, 2], 3)
    assert tasks == [(0, "scripted", 0), (0, "random", 0), (0, "random", 1), (0, "random", 2),
                     (2, "scripted", 0), (2, "random", 0), (2, "random", 1), (2, "random", 2)]


@pytest.mark.slow
def test_in_process_sweep_writes_a_summary(tmp_path, capsys):
    out, png = tmp_path / "s.json", tmp_path / "s.png"
    assert sweep.main(["--workers", "0", "--episodes", "2", "--levels", "2", "--out", str(out),
                       "--plot", str(png), "--no-progress"]) == 0
    summary = json.loads(out.read_text())
    rows = {(r["name"], r["agent"]): r for r in summary["rows"]}
    assert rows["Hills", "scripted"]["completion_rate"] == 1.0  # the demo finishes its level
    assert rows["Hills", "random"]["episodes"] == 2
    assert summary["frames"] == sum(r["frames"] for r in summary["episodes_detail"])
    assert summary["frames_per_second"] > 0
    printed = capsys.readouterr().out
    assert "Hills" in printed and "summary:" in printed
    if importlib.util.find_spec("matplotlib") is None:  # (the plot needs it; the summary does not)
        assert "no plot: matplotlib is not installed" in printed and not png.exists()
    else:  # a 6 x 3.2 inch chart at 100 dpi
        data = png.read_bytes()
        assert f"plot: {png}" in printed and data[:8] == b"\x89PNG\r\n\x1a\n"
        assert (int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")) == (600, 320)


@pytest.mark.slow
def test_the_random_agent_is_deterministic_per_seed():
    a = sweep.run_episode((0, "random", 5), max_frames=600)
    b = sweep.run_episode((0, "random", 5), max_frames=600)
    assert {k: v for k, v in a.items() if k != "seconds"} == {k: v for k, v in b.items() if k != "seconds"}


@pytest.mark.parametrize("argv, message", [
    (["--levels", "7"], "there is no level 7"),
    (["--levels", "one"], "level indices"),
    (["--workers", "-1"], "--workers must be >= 0"),
    (["--episodes", "0"], "must be >= 1"),
])
def test_bad_arguments_are_clear_errors(argv, message, capsys, tmp_path):
    assert sweep.main([*argv, "--out", str(tmp_path / "x.json"), "--no-progress"]) == 2
    assert message in capsys.readouterr().err


def test_workers_without_ray_is_a_clear_error(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)  # as if ray were not installed
    assert sweep.main(["--workers", "2", "--out", str(tmp_path / "x.json"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "--workers 2 needs Ray" in err and "--workers 0" in err


@pytest.mark.slow
def test_a_sweep_on_ray_gives_the_in_process_results(tmp_path):
    pytest.importorskip("ray", reason="the rl extra (ray) is not installed: pip install -e '.[rl]'")
    tasks = sweep.tasks_for([2], 2)
    local, _ = sweep.run_tasks(tasks, 0, max_frames=900, progress=False)
    remote, _ = sweep.run_tasks(tasks, 2, max_frames=900, progress=False)

    def strip(rs):
        return [{k: v for k, v in r.items() if k != "seconds"} for r in rs]

    assert strip(remote) == strip(local)
