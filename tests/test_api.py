"""The public surface is declared: every module of the package and of the examples has an
``__all__`` (what the API page shows, see docs/api.md), and every name in it is defined there.

Read from the source (no import), so the optional extras' modules are checked without them."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODULES = sorted(p for d in ("framework", "examples") for p in (ROOT / d).rglob("*.py"))


def _top_level_names(tree: ast.Module) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(tree):  # (names bound under `if`/`try` at the top level count too)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
    return names


def _declared(tree: ast.Module) -> list[str] | None:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, ast.AnnAssign) and node.value is not None else []
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return list(ast.literal_eval(node.value))  # type: ignore[union-attr]  # (AnnAssign: value given)
    return None


@pytest.mark.parametrize("path", MODULES, ids=[str(p.relative_to(ROOT)) for p in MODULES])
def test_every_module_declares_its_public_names(path):
    tree = ast.parse(path.read_text())
    declared = _declared(tree)
    assert declared is not None, f"{path.relative_to(ROOT)} has no __all__"
    missing = [n for n in declared if n not in _top_level_names(tree)]
    assert not missing, f"{path.relative_to(ROOT)}: __all__ names {missing}, which it does not define"
    assert len(set(declared)) == len(declared), f"{path.relative_to(ROOT)}: a name is in __all__ twice"


def test_the_names_a_game_maker_reaches_for_are_at_the_top():
    # (issue 36: the controller, Visual, Input and the render entry points, as `from arcade import ...`)
    import subprocess
    import sys

    code = ("import sys\n"
            "from framework import CharacterController, Input, Visual, Scene, Hitbox, Transform, Velocity\n"
            "assert not any(m.startswith('pyglet') for m in sys.modules), 'pyglet loaded before it was asked for'\n"
            "from framework import Camera, Renderer, run, screenshot\n"
            "import framework.render as r, framework.character as c, framework.input as i\n"
            "assert (run, Renderer, Camera, screenshot) == (r.run, r.Renderer, r.Camera, r.screenshot)\n"
            "assert (CharacterController, Input) == (c.CharacterController, i.Input)\n"
            "print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr
