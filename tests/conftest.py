"""Shared test set-up."""

import os

# Rendering tests (tests/test_render.py): headless OpenGL through EGL (Mesa's llvmpipe). pyglet
# reads these when its window / GL modules are first imported, so they are set before any test
# module is collected. PYGLET_HEADLESS=0 in the environment uses a real display instead.
os.environ.setdefault("PYGLET_HEADLESS", "1")
os.environ.setdefault("PYGLET_SHADOW_WINDOW", "0")

import pytest  # noqa: E402


@pytest.fixture(scope="module")
def render():
    """``framework.render``, with the hidden offscreen window's GL context made; the test is skipped,
    with the reason, only where no OpenGL library can make a context."""
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the code under test
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    return render
