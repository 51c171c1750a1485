"""The README's Python example, run as written: it must print a helium energy above the exact one."""
import contextlib
import io
import re

from conftest import ROOT


def python_example() -> str:
    blocks = re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(), re.S | re.M)
    assert len(blocks) == 1, f"README.md has {len(blocks)} ```python blocks, this test runs exactly one"
    return blocks[0]


def test_readme_python_example(references):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(python_example(), str(ROOT / "README.md"), "exec"), {"__name__": "readme"})
    energy = float(out.getvalue().split()[-1])
    exact = references["He"]["energy"]
    # variational: above the exact energy; 100 functions with two sweeps give 7.0e-6 Eh above (14 s)
    assert exact < energy < exact + 1e-5, energy
