"""`prebo import`: an ecgpack / ATOM-MOL-nonBO basis as basis.json (the module's name, `import_`, is
Python's keyword with PEP 8's trailing underscore)."""
from __future__ import annotations

from pathlib import Path

from .files import given, output_file


def add(sub) -> None:
    """The `prebo import` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("import", help="convert an ecgpack / ATOM-MOL-nonBO FILE.inout.txt to basis.json")
    p.add_argument("file", help="ecgpack FILE.inout.txt (RG_0S: real plain ECGs; RG_1P: P states)")
    p.add_argument("--out", help="basis.json to write (default FILE.json)")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.add_argument("--c-A", dest="c_A", type=float, default=1.0, help="CM exponent c_A of the LFCC functions")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo import FILE.inout.txt [--out X.json] [--force] [--c-A C]`: an ecgpack basis as basis.json."""
    from ..eigen import THRESHOLD
    from ..io import stored
    from ..io.ecgpack import read_inout
    from ..optimise.settings import check

    c_A = check("c_A", args.c_A, "--c-A")
    default = Path(stored.stem(args.file) + ".json")
    out = output_file(given(args.out, default, "a file name"), args.force, [args.file])
    basis = read_inout(args.file, c_A=c_A)
    basis.save(out, {"optimiser": {"threshold": THRESHOLD}})  # every direction kept, as ecgpack solves it
    print(f"wrote {out} ({len(basis)} {basis.family.name} functions, {basis.system.label()})")
    return 0
