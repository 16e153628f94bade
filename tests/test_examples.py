"""The small examples (docs/examples.md) run headless and say what they did.

Each is run as a user would, ``python -m examples.NAME --headless --frames 60``, in a subprocess;
its last line of stdout is a one-line JSON summary.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ["bounce", "shapes_overlay", "line_of_sight", "bullet_hell"]


def run_example(name: str, *args: str) -> dict:
    out = subprocess.run([sys.executable, "-m", f"examples.{name}", "--headless", *args], cwd=ROOT,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout.strip().splitlines()[-1])
    assert summary["example"] == name
    return summary


@pytest.fixture(scope="module")
def summaries() -> dict[str, dict]:
    return {name: run_example(name, "--frames", "60") for name in EXAMPLES}


def test_bounce_the_squares_meet_and_swap_directions(summaries):
    s = summaries["bounce"]
    assert s["frames"] == 60
    # 220 units apart, closing at 400 units/s: they first overlap in step 33 (0.55 s).
    assert s["bounces"] == 1 and s["first_bounce_frame"] == 33
    assert s["velocities"] == [-200.0, 200.0]  # elastic, equal masses: each goes back the way it came


def test_shapes_overlay_tests_circles_and_polygons(summaries):
    s = summaries["shapes_overlay"]
    assert s["frames"] == 60 and s["bodies"] == 30 and s["screenshot"] is None
    assert s["peak_contacts"] > 0
    assert {"circle-circle", "polygon-polygon"} <= set(s["narrow_tests"])
    assert any("circle" in k and "polygon" in k for k in s["narrow_tests"])


def test_line_of_sight_sees_the_runner_and_loses_it(summaries):
    s = summaries["line_of_sight"]
    assert s["frames"] == 60 and s["seen_frames"] + s["hidden_frames"] == 60
    assert s["seen_frames"] > 0 and s["hidden_frames"] > 0  # pillars hide it part of the time
    assert s["first_seen_frame"] is not None


def test_bullet_hell_reports_bodies_and_stage_times(summaries):
    s = summaries["bullet_hell"]
    assert s["frames"] == 60
    assert s["bodies"] == 1 + 60 * 12  # the ship and 12 bullets a step, none expired yet
    # Only the declared effects' stages run: no response, no render (headless).
    assert set(s["stage_ms"]) == {"movement", "broad_phase", "narrow_phase"}
    assert all(ms >= 0.0 for ms in s["stage_ms"].values())


def test_the_summaries_in_the_docs_are_what_the_examples_print(summaries):
    # docs/examples.md shows each example's `--headless --frames 60` line. Timings vary by machine,
    # and the contact counts follow the solver's details: for those only the kind of value is checked.
    volatile = {"stage_ms", "narrow_tests", "peak_contacts"}
    text = (ROOT / "docs" / "examples.md").read_text()
    shown = [json.loads(line) for line in re.findall(r"^(\{\"example\".*\})$", text, flags=re.M)]
    assert sorted(s["example"] for s in shown) == sorted(EXAMPLES)
    for doc in shown:
        actual = summaries[doc["example"]]
        assert set(doc) == set(actual)
        for key, value in doc.items():
            if key in volatile:
                assert type(value) is type(actual[key]), key
            else:
                assert value == actual[key], (doc["example"], key)


@pytest.mark.parametrize("name", EXAMPLES)
def test_each_example_is_one_short_file_with_the_common_options(name):
    text = (ROOT / "examples" / f"{name}.py").read_text()
    assert len(text.splitlines()) < 100
    assert "--headless" in text and "--frames" in text and "framework.render import run" in text
    assert f"`examples/{name}.py`" in (ROOT / "docs" / "examples.md").read_text()


def test_shapes_overlay_writes_a_screenshot_with_the_overlay(tmp_path):
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the example
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    path = tmp_path / "shapes.png"
    s = run_example("shapes_overlay", "--frames", "20", "--screenshot", str(path))
    assert s["screenshot"] == str(path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
