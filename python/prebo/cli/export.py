"""`prebo export`: a plain-ECG basis, or an ECG-GVR one of a P state, in another code's format."""
from __future__ import annotations

from pathlib import Path

from ..io.load import load_basis
from .files import given, output_file


def add(sub) -> None:
    """The `prebo export` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("export", help="write a plain-ECG basis (or ECG-GVR, N = 1, K = 0) in another code's format")
    p.add_argument("basis", help="basis.json")
    p.add_argument("--format", choices=["ecgpack"], required=True)
    p.add_argument("--out", help="file to write (default BASIS.inout.txt)")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo export BASIS.json --format ecgpack [--out FILE] [--force]`: a plain-ECG basis as an ecgpack
    RG_0S file, an ECG-GVR one of N = 1 and K = 0 as RG_1P (prebo.io.ecgpack)."""
    from ..io import stored
    from ..io.ecgpack import write_inout

    default = Path(stored.stem(args.basis) + ".inout.txt")
    out = output_file(given(args.out, default, "a file name"), args.force, [args.basis])
    basis, _ = load_basis(args.basis)
    write_inout(basis, out)
    print(f"wrote {out}")
    return 0
