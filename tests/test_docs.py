"""The docs cannot rot.

- Every ``>>>`` sample in docs/*.md runs as a doctest.
- Every complete ```python block runs: on the pages listed in ``EVERY_BLOCK_RUNS`` all of them
  (fragments there are written as ``>>>`` doctests instead), elsewhere the ones marked with a
  ``<!-- runnable -->`` line just above. A ```text block right after a runnable block is what it
  prints, exactly. A block calling ``framework.render.run`` gets a stand-in that checks the
  arguments against the real signature and steps the scene headless instead of opening a window.
- A block marked ``<!-- pytest -->`` is a test file: it runs under pytest in another process (the
  plugin as installed, as in a game's own suite), and every test in it passes; the one using the
  ``golden_dir`` fixture goes through a golden file's life instead (fails unrecorded, records,
  passes, fails when the behaviour changes).
- The README's example runs and prints what its comments say; its links lead somewhere.
- The site's navigation (mkdocs.yml) lists every page, and lists no page that is missing.
- The site builds with ``mkdocs build --strict``; its API page shows each module's ``__all__`` only.
- Every parameter of ``Scene``, ``Hitbox``, ``Visual`` and ``CharacterController``, and every public
  method and attribute of ``Input``, is in docs/api.md's tables ("At a glance"), with its true
  default; docs/concepts.md's component table names every constructor parameter.
- Output the docs show is what the code prints today: a ``$ python -m ...`` line in a ```sh block
  is run and its output compared (JSON lines field by field, wall-clock timings excepted), so are
  the examples' summary lines on docs/examples.md, and the replay file docs/reliability.md shows
  is what its sample writes.
"""

from __future__ import annotations

import dataclasses
import doctest
import enum
import importlib
import importlib.util
import inspect
import json
import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
DOC_FILES = sorted(p for p in DOCS.rglob("*.md") if ">>>" in p.read_text())
# Pages on which every ```python block is a complete program (or a >>> doctest), and runs.
EVERY_BLOCK_RUNS = {"index.md", "concepts.md", "events.md", "examples.md", "api.md"}
RUNNABLE_MARK = "<!-- runnable -->"
PYTEST_MARK = "<!-- pytest -->"
_PYTEST_BLOCK = re.compile(r"<!-- pytest -->\n```python\n(?P<code>.*?)```\n", re.S)
_BLOCK = re.compile(r"(?P<mark><!-- runnable -->\n)?```python\n(?P<code>.*?)```\n"
                    r"(?:\n(?:[^`\n][^\n]*\n)*?\n?```text\n(?P<out>.*?)```)?", re.S)


@pytest.mark.parametrize("path", DOC_FILES, ids=lambda p: p.name)
def test_doctests_in_docs(path):
    result = doctest.testfile(str(path), module_relative=False, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} doctest failures in {path.name}"


def _python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def _runnable_blocks() -> list[tuple[str, int, str, str | None]]:
    """(page, block number on the page, code, expected output or None) of every block that runs."""
    found = []
    for path in sorted(DOCS.glob("*.md")):
        for i, m in enumerate(_BLOCK.finditer(path.read_text()), 1):
            code = m.group("code")
            if code.lstrip().startswith(">>>"):
                continue  # a doctest: test_doctests_in_docs runs it
            if path.name in EVERY_BLOCK_RUNS or m.group("mark"):
                found.append((path.name, i, code, m.group("out")))
    return found


RUNNABLE = _runnable_blocks()


def test_the_pages_that_run_every_block_exist_and_have_blocks():
    for name in EVERY_BLOCK_RUNS:
        assert (DOCS / name).exists(), name
    assert {"index.md", "concepts.md"} <= {page for page, *_ in RUNNABLE}


@pytest.mark.parametrize("page,number,code,expected", RUNNABLE, ids=[f"{p}#{n}" for p, n, _c, _o in RUNNABLE])
def test_complete_python_blocks_in_docs_run(page, number, code, expected, capsys, monkeypatch, tmp_path):
    if "framework.render" in code:
        import framework.render

        real_run = framework.render.run

        def headless_run(scene, *args, **kwargs):  # the window runner, minus the window
            inspect.signature(real_run).bind(scene, *args, **kwargs)
            for _ in range(kwargs.get("max_frames") or 60):
                scene.step(1.0 / kwargs.get("fps", 60))

        monkeypatch.setattr(framework.render, "run", headless_run)
    monkeypatch.chdir(tmp_path)  # whatever a sample writes lands in a temporary directory
    exec(compile(code, f"docs/{page} (python block {number})", "exec"), {"__name__": "__main__"})
    out = capsys.readouterr().out
    if expected is not None:
        assert out == expected, f"docs/{page} block {number} printed:\n{out}"


def _pytest_blocks() -> list[tuple[str, int, str]]:
    """(page, block number among the page's test-file blocks, code) of every ``<!-- pytest -->``
    block."""
    return [(path.name, i, m.group("code")) for path in sorted(DOCS.glob("*.md"))
            for i, m in enumerate(_PYTEST_BLOCK.finditer(path.read_text()), 1)]


PYTEST_BLOCKS = _pytest_blocks()
GOLDEN_BLOCKS = [b for b in PYTEST_BLOCKS if "golden_dir" in b[2]]


def test_the_testing_page_samples_are_test_files():
    on_testing = [b for b in PYTEST_BLOCKS if b[0] == "testing.md"]
    assert len(on_testing) >= 6 and len(GOLDEN_BLOCKS) == 1
    assert RUNNABLE_MARK not in (DOCS / "testing.md").read_text()  # they run under pytest, not as scripts


def _pytest_in_a_process(pytester, *args):
    """pytest in another process, in ``pytester``'s folder; its outcomes and output."""
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", *args)
    return result.parseoutcomes(), result.stdout.str()


@pytest.mark.slow
@pytest.mark.parametrize("page,number,code", [b for b in PYTEST_BLOCKS if b not in GOLDEN_BLOCKS],
                         ids=[f"{p}#{n}" for p, n, c in PYTEST_BLOCKS if (p, n, c) not in GOLDEN_BLOCKS])
def test_test_file_blocks_in_docs_pass_under_pytest(page, number, code, pytester):
    tests = re.findall(r"^def (test_\w+)\(", code, flags=re.M)
    assert tests, f"docs/{page} test file {number} has no test function"
    pytester.makepyfile(test_sample=code)
    outcomes, out = _pytest_in_a_process(pytester, "--no-framework-pictures")
    assert outcomes == {"passed": len(tests)}, f"docs/{page} test file {number}:\n{out[-4000:]}"


@pytest.mark.slow
def test_the_golden_sample_records_once_and_then_can_fail(pytester, monkeypatch):
    """The page's golden sample, as its text says: the first run fails for want of a golden file,
    ``--update-golden`` records it next to the test, the same run then passes, and a change of
    behaviour fails at the first step that differs."""
    monkeypatch.delenv("FRAMEWORK_UPDATE_GOLDEN", raising=False)
    ((page, number, code),) = GOLDEN_BLOCKS
    original = "Velocity(3.0, 0.0)"
    assert original in code, f"docs/{page} test file {number}: the test below changes the ball's {original}"
    pytester.mkdir("tests")
    test_file = pytester.path / "tests" / "test_ball.py"
    test_file.write_text(code)
    golden = pytester.path / "tests" / "golden" / "ball.json"
    outcomes, out = _pytest_in_a_process(pytester, "--no-framework-pictures", "tests")
    assert outcomes == {"failed": 1} and f"no golden file {golden}" in out and "--update-golden" in out, out[-4000:]
    outcomes, out = _pytest_in_a_process(pytester, "tests", "--update-golden")
    assert outcomes == {"passed": 1} and golden.exists(), out[-4000:]
    outcomes, out = _pytest_in_a_process(pytester, "tests")
    assert outcomes == {"passed": 1}, out[-4000:]
    test_file.write_text(code.replace(original, "Velocity(3.25, 0.0)"))
    outcomes, out = _pytest_in_a_process(pytester, "--no-framework-pictures", "tests")
    assert outcomes == {"failed": 1}, out[-4000:]
    said = ("step 1 of 240 (frame 1) differs from the golden run: entity 18 x: golden 2.55, now 2.5541666666666667 "
            "(differs by 0.00417)")
    assert f"tests/golden/ball.json: {said}" in (DOCS / page).read_text()  # what the page shows ...
    assert f"{golden}: {said}" in out, out[-4000:]  # ... is what it says


def test_readme_example_runs_and_prints_what_it_says(capsys):
    (block,) = [b for b in _python_blocks(ROOT / "README.md") if "Scene(" in b]
    exec(compile(block, "README.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    # The comments in the block say what it prints.
    expected = re.findall(r"# (\[.*?\]|[0-9.]+):", block)
    assert out == expected


def test_readme_links_lead_to_files():
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", (ROOT / "README.md").read_text())
    local = [link for link in links if "://" not in link]
    assert local, "the README links into the docs"
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing, f"README links to missing files: {missing}"


def test_site_navigation_lists_every_page_and_only_pages_that_exist():
    nav = re.findall(r"^\s*- [^:\n]+: (\S+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), flags=re.M)
    pages = sorted(p.name for p in DOCS.glob("*.md"))
    assert sorted(set(nav)) == sorted(nav), "a page is listed twice"
    assert sorted(set(pages) - set(nav)) == [], "pages missing from the nav in mkdocs.yml"
    assert sorted(set(nav) - set(pages)) == [], "mkdocs.yml lists pages that do not exist"


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None,
                    reason="the docs extra is not installed (pip install -e '.[docs]')")
def test_site_builds_strict(tmp_path):
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert out.returncode == 0, out.stderr[-4000:]
    assert (tmp_path / "site" / "api" / "index.html").exists()
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    assert "<code>Camera</code>" in api and not re.search(r":(class|func|meth|mod|attr):<code>", api), \
        "Sphinx roles in docstrings must render as plain code (docs_hooks/sphinx_roles.py)"
    # The API page lists each module's public names: those in its __all__, and nothing else.
    ids = set(re.findall(r'id="(framework[\w.]*)"', api))
    modules = re.findall(r"^::: (framework(?:\.\w+)*)\s*$", (DOCS / "api.md").read_text(), flags=re.M)
    for name in modules:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError:  # a function of a module (framework.collision.collide.collide)
            continue
        if not hasattr(module, "__all__") or name == "framework":  # (the package: members: false)
            continue
        shown = {i[len(name) + 1:] for i in ids if i.startswith(name + ".") and "." not in i[len(name) + 1:]}
        extra = shown - set(module.__all__)
        assert not extra, f"the API page shows {sorted(extra)} of {name}, which are not in its __all__"


@pytest.mark.slow
def test_the_pythonpath_setting_on_the_testing_page_makes_a_games_modules_importable(tmp_path):
    """docs/testing.md's layout, as the page says: a game's test imports the game's own module;
    under the plain ``pytest`` command (which puts no current folder on ``sys.path``: ``python -P``)
    that fails without the page's ``pythonpath`` setting and passes with it."""
    page = (DOCS / "testing.md").read_text()
    (settings,) = re.findall(r"```toml\n(.*?)```", page, flags=re.S)
    assert 'pythonpath = ["."]' in settings
    (tmp_path / "mygame").mkdir()
    (tmp_path / "mygame" / "__init__.py").write_text("SPEED = 5.0\n")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_mygame.py").write_text("import mygame\n\n\ndef test_speed():\n"
                                                       "    assert mygame.SPEED == 5.0\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # this checkout's framework, whatever is installed

    def pytest_there() -> str:
        command = [sys.executable, "-P", "-m", "pytest", "-p", "no:cacheprovider", "--no-framework-pictures"]
        out = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
        return out.stdout + out.stderr

    (tmp_path / "pyproject.toml").write_text("[project]\nname = 'mygame'\n")
    out = pytest_there()
    assert "ModuleNotFoundError: No module named 'mygame'" in out, out[-4000:]
    (tmp_path / "pyproject.toml").write_text("[project]\nname = 'mygame'\n\n" + settings)
    out = pytest_there()
    assert "1 passed" in out and "error" not in out.lower(), out[-4000:]


# --- the reference: every public parameter, with its default --------------------------------------

_REQUIRED = object()


def _reference_classes() -> list[type]:
    from framework import CharacterController, Hitbox, Input, Scene, Visual

    return [Scene, Hitbox, Visual, CharacterController, Input]


def _parameters(cls: type) -> dict[str, object]:
    """The public parameters a game passes to ``cls`` (a dataclass: its fields), and their defaults."""
    if dataclasses.is_dataclass(cls):
        return {f.name: (f.default if f.default is not dataclasses.MISSING
                         else f.default_factory() if f.default_factory is not dataclasses.MISSING else _REQUIRED)
                for f in dataclasses.fields(cls) if not f.name.startswith("_")}
    return {name: (_REQUIRED if p.default is inspect.Parameter.empty else p.default)
            for name, p in inspect.signature(cls).parameters.items() if not name.startswith("_")}


def _reference_section(name: str) -> str:
    """docs/api.md's "At a glance" section about ``name``: from its heading to the next heading."""
    text = (DOCS / "api.md").read_text()
    found = re.search(rf"^### `{name}(?:\(\.\.\.\))?`\n(.*?)(?=^#|^:::)", text, flags=re.S | re.M)
    assert found, f"docs/api.md has no section ### `{name}(...)`"
    return found.group(1)


def _rows(section: str) -> dict[str, list[str]]:
    """A section's table rows by their first cell's code (`name`), the other cells as written."""
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| `") and cells:
            rows[cells[0].strip("`")] = cells[1:]
    return rows


@pytest.mark.parametrize("cls", _reference_classes()[:4], ids=lambda c: c.__name__)
def test_every_public_parameter_is_in_the_reference_with_its_default(cls):
    params = _parameters(cls)
    assert params, cls
    section = _reference_section(cls.__name__)
    rows = _rows(section)
    assert sorted(set(params) - set(rows)) == [], f"docs/api.md's {cls.__name__} table misses parameters"
    assert sorted(set(rows) - set(params)) == [], f"docs/api.md's {cls.__name__} table has rows that are not parameters"
    for name, default in params.items():
        shown = rows[name][0]
        if default is _REQUIRED:
            assert shown == "required", (cls.__name__, name, shown)
            continue
        assert shown.startswith("`") and shown.endswith("`"), (cls.__name__, name, shown)
        value = eval(shown.strip("`"), {"math": math})
        if isinstance(default, enum.Enum):
            default = default.value  # (Hitbox's body: its name, as a game writes it)
        assert value == default and type(value) is type(default), \
            f"docs/api.md: {cls.__name__} {name} defaults to {default!r}, the table says {shown}"
    # The signature line above the table names parameters only.
    (signature,) = re.findall(rf"^`{cls.__name__}\((.*?)\)`", section, flags=re.S | re.M)[:1]
    named = re.findall(r"(\w+)=", signature)
    assert named and set(named) <= set(params), (cls.__name__, named)


def test_inputs_public_methods_and_attributes_are_in_the_reference():
    from framework.input import Input

    rows = _rows(_reference_section("Input"))
    methods = {name: fn for name, fn in vars(Input).items() if not name.startswith("_") and callable(fn)}
    assert {"press", "release", "set_held", "is_held", "was_pressed", "was_released"} <= set(methods)
    for name, fn in methods.items():
        params = list(inspect.signature(fn).parameters.values())[1:]  # (not self)
        call = f"{name}({', '.join(('*' if p.kind is p.VAR_POSITIONAL else '') + p.name for p in params)})"
        assert call in rows, f"docs/api.md's Input table has no row `{call}`"
    attributes = sorted(a for a in vars(Input()) if not a.startswith("_"))
    assert attributes == ["held", "pressed", "released"]
    assert ", ".join(f"`{a}`" for a in attributes) in (DOCS / "api.md").read_text()


def test_the_concepts_component_table_names_every_constructor_parameter():
    text = (DOCS / "concepts.md").read_text()
    checked = []
    for cls in _reference_classes()[1:4]:
        (listed,) = re.findall(rf"^\| `{cls.__name__}\((.*?)\)` \|", text, flags=re.M)
        names = [n.strip().lstrip("*") for n in listed.split(",") if n.strip() not in ("*", "")]
        params = list(_parameters(cls))
        if names[-1] == "...":  # the first parameters, in order, then the rest left out
            names = names[:-1]
            params = params[:len(names)]
        assert names == params, f"docs/concepts.md lists {cls.__name__}({listed}); its parameters are {params}"
        checked.append(cls.__name__)
    assert checked == ["Hitbox", "Visual", "CharacterController"]


# --- output shown in the docs is what the code prints ------------------------------------------------

# The fields of a shown JSON line that are measured wall-clock time, different on every run: the
# only ones allowed to differ (the platformer's summary: ms_per_frame, time per simulated frame;
# bullet_hell's: stage_ms, each stage's milliseconds).
TIMINGS = {"ms_per_frame", "stage_ms"}


def _same_but_timings(want: str, got: str) -> set[str]:
    """The fields, timings aside, in which two JSON lines differ (both must have the same fields)."""
    want_fields, got_fields = json.loads(want), json.loads(got)
    assert set(want_fields) == set(got_fields), f"shown: {want}\nprinted: {got}"
    return {k for k in want_fields if want_fields[k] != got_fields[k]} - TIMINGS


def _shown_runs() -> list[tuple[str, str, list[str]]]:
    """(page, command, the output lines shown under it) of every ``$ command`` line in a ```sh block
    of the docs or the README."""
    found = []
    for path in [*sorted(DOCS.glob("*.md")), ROOT / "README.md"]:
        for block in re.findall(r"```sh\n(.*?)```", path.read_text(), flags=re.S):
            command = None
            for line in block.splitlines():
                if line.startswith("$ "):
                    command = line[2:].strip()
                    found.append((path.name, command, []))
                elif command is not None:
                    found[-1][2].append(line)
    return found


SHOWN_RUNS = _shown_runs()


def test_the_docs_show_runs_with_their_output():
    assert ("platformer.md", "python -m examples.platformer --headless --demo") in {(p, c) for p, c, _ in SHOWN_RUNS}


@pytest.mark.slow
@pytest.mark.parametrize("page,command,shown", SHOWN_RUNS, ids=[f"{p}:{c}" for p, c, _ in SHOWN_RUNS])
def test_a_run_shown_in_the_docs_prints_what_it_shows(page, command, shown):
    words = shlex.split(command)
    assert words[:2] == ["python", "-m"], f"docs/{page}: only `$ python -m ...` runs are checked, not {command!r}"
    out = subprocess.run([sys.executable, *words[1:]], cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode == 0, out.stderr[-4000:]
    printed = out.stdout.splitlines()[-len(shown):] if shown else []
    assert len(printed) == len(shown), f"docs/{page}: {command} printed\n{out.stdout}"
    for want, got in zip(shown, printed):
        if want.startswith("{"):
            differ = _same_but_timings(want, got)
            assert not differ, f"docs/{page}: {command} now prints {got} (differs in {sorted(differ)})"
        else:
            assert got == want, f"docs/{page}: {command} printed\n{out.stdout}"


@pytest.mark.slow
def test_the_examples_summaries_shown_are_what_they_print():
    """docs/examples.md shows each example's summary line, as the page says, of
    ``python -m examples.NAME --headless --frames 60``; every field but the timings is checked
    (tests/test_examples.py checks the rest of what they print)."""
    shown = re.findall(r'^(\{"example": "(\w+)".*\})$', (DOCS / "examples.md").read_text(), flags=re.M)
    assert len(shown) == 4
    for line, name in shown:
        out = subprocess.run([sys.executable, "-m", f"examples.{name}", "--headless", "--frames", "60"], cwd=ROOT,
                             capture_output=True, text=True, timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
        assert out.returncode == 0, out.stderr[-4000:]
        printed = out.stdout.splitlines()[-1]
        differ = _same_but_timings(line, printed)
        assert not differ, f"docs/examples.md: {name} now prints {printed} (differs in {sorted(differ)})"


def test_the_replay_file_shown_is_what_the_sample_writes(tmp_path):
    from framework.replay import Replay

    page = (DOCS / "reliability.md").read_text()
    (shown,) = [b for b in re.findall(r"```text\n(.*?)```", page, flags=re.S) if '"framework-replay"' in b]
    (made,) = re.findall(r"^>>> replay = (Replay\(.*\))$", page, flags=re.M)
    replay = eval(made, {"Replay": Replay})
    replay.save(tmp_path / "run.replay")
    assert (tmp_path / "run.replay").read_text() == shown


def test_the_quick_run_the_docs_show_uses_a_registered_marker_and_the_default_runs_everything():
    import tomllib

    pytest_settings = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert any(m.startswith("slow:") for m in pytest_settings["markers"])
    assert "-m" not in pytest_settings["addopts"].split(), "the default run (CI's) must select every test"
    for page in ("README.md", "CONTRIBUTING.md"):
        assert 'pytest -m "not slow"' in (ROOT / page).read_text(), page
