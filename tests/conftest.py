"""Shared test set-up."""

import os

# Rendering tests (tests/test_render.py): headless OpenGL through EGL (Mesa's llvmpipe). pyglet
# reads these when its window / GL modules are first imported, so they are set before any test
# module is collected. PYGLET_HEADLESS=0 in the environment uses a real display instead.
os.environ.setdefault("PYGLET_HEADLESS", "1")
os.environ.setdefault("PYGLET_SHADOW_WINDOW", "0")
