"""docs/tutorial.md, run as written: its TOML file saved under the name the text gives, every line of
its ```sh blocks run as a `prebo` command in a scratch folder with examples/ beside it, its
```python block executed there; every command must succeed, the run's levels must lie above the
literature values (variational), and the outputs the text names must exist."""
import contextlib
import io
import json
import re
import shlex

from prebo.cli import main

from conftest import ROOT

TUTORIAL = (ROOT / "docs" / "tutorial.md").read_text()


def blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", TUTORIAL, re.S | re.M)


def test_the_tutorial_runs_as_written(tmp_path, monkeypatch, references):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    (toml,) = blocks("toml")
    (name,) = re.findall(r"Save this as `([^`]+)`", TUTORIAL)
    (tmp_path / name).write_text(toml)
    commands = [line for block in blocks("sh") for line in block.splitlines() if line.strip()]
    assert commands and all(c.startswith("prebo ") for c in commands), commands
    for command in commands:
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(shlex.split(command)[1:]) == 0, command
    result = json.loads((tmp_path / "runs" / "ladder" / "result.json").read_text())
    literature = [references[k]["energy"] for k in ("H2+", "H2+ v=1", "H2+ v=2", "H2+ v=3")]
    energies = [level["energy"] for level in result["levels"]]
    # the input's proton mass, 1836.15267, moves the levels by ~1e-12 Eh from the references'
    assert len(energies) == 4 and all(e > ref - 1e-9 for e, ref in zip(energies, literature)), (energies, literature)
    for output in ("runs/ladder/convergence.png", "ladder-densities.png", "ladder-densities.csv", "he-alpha.png"):
        assert (tmp_path / output).stat().st_size > 0, output
    (python,) = blocks("python")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(python, str(ROOT / "docs" / "tutorial.md"), "exec"), {"__name__": "tutorial"})
    energy, r_pp, breit_pauli = map(float, out.getvalue().split())
    # the stored result's energy, to the last bits a BLAS kernel may change; a Breit–Pauli
    # correction between hydrogen 1s's, −1.46 cm⁻¹, and He⁺ 1s's, 16 times that
    assert abs(energy - energies_of_stored_basis()[1]) < 1e-13 and 2.0 < r_pp < 3.0, (energy, r_pp)
    assert -16 * 1.46 < breit_pauli < -1.46, breit_pauli


def energies_of_stored_basis() -> list[float]:
    return [level["energy"] for level in
            json.loads((ROOT / "examples" / "bases" / "h2plus-ladder" / "result.json").read_text())["levels"]]
