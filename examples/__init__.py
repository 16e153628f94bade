"""Runnable examples built on the framework.

From a checkout they are ``examples`` (``python -m examples.platformer``); installed (``pip install
framework``) the same files are ``framework.examples`` (``python -m framework.examples.platformer``),
inside the framework's own package so that no other project's ``examples`` can collide with them.
"""

__all__: list[str] = []  # the examples are modules, each run as a program (python -m ...)
