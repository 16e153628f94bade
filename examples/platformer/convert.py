"""Convert a text map to a Tiled map: ``python -m examples.platformer.convert IN.txt OUT.tmj [TITLE]``.

How the shipped ``levels/*.tmj`` were first written; open them in Tiled to edit them further.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from .levels import dump_tmj, load_level, parse_tmj, to_tmj

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) not in (2, 3):
        print(__doc__.strip().splitlines()[0], file=sys.stderr)
        return 2
    level = load_level(args[0])
    out = Path(args[1])
    out.write_text(dump_tmj(to_tmj(level, args[2] if len(args) == 3 else None)), encoding="utf-8")
    parse_tmj(json.loads(out.read_text(encoding="utf-8")), str(out))  # it loads back
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
