"""mkdocs hook: render the Sphinx cross-reference roles of our docstrings as plain code.

The docstrings say ``:class:`~framework.render.camera.Camera``` (read well in an editor and by
``help()``); mkdocstrings' Python handler does not resolve those roles and would show the role
name literally. This drops the role and, for ``~`` references, keeps the last name only.
"""

from __future__ import annotations

import re

_ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj):(<code>)(~?)([\w.]+)(</code>)")


def _sub(m: re.Match[str]) -> str:
    name = m.group(3).rsplit(".", 1)[-1] if m.group(2) else m.group(3)
    return f"{m.group(1)}{name}{m.group(4)}"


def on_page_content(html: str, **_kwargs) -> str:
    return _ROLE.sub(_sub, html)
