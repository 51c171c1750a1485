"""Version and provenance (issue 59): `prebo --version` and `prebo.__version__` from one source (the
Cargo workspace, through the package metadata), and every result.json, basis.json and checkpoint
records what made it; files without the record, from earlier versions, still load."""
import json
import platform
import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

import prebo
from prebo import _core
from prebo.cli import main
from prebo.errors import BasisFileError
from prebo.provenance import commit

ROOT = Path(__file__).resolve().parents[1]
H_TOML = '[system]\nparticles = ["p", "e"]\n[basis]\nsize = 3\n[optimiser]\ntrials = 4\nseed = 3\n'


def test_one_version_everywhere(capsys):
    """The Cargo workspace's version is the package's, `prebo.__version__` and `prebo --version`'s."""
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["package"]["version"]
    assert metadata.version("prebo") == cargo == prebo.__version__
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.split()[:2] == ["prebo", cargo]


def test_the_commit_is_this_checkouts():
    """Imported from a checkout, the commit is its HEAD (with "+modified" for edited tracked files);
    the core records the commit it was built from (40 hexadecimal digits in a checkout)."""
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True)
    if head.returncode != 0:
        pytest.skip("not a git checkout")
    assert re.fullmatch(r"[0-9a-f]{40}(\+modified)?", commit()) and commit().startswith(head.stdout.strip())
    assert re.fullmatch(r"[0-9a-f]{40}", _core.GIT_COMMIT)


def test_every_output_of_a_run_carries_its_provenance(tmp_path, capsys):
    """result.json, the checkpoint basis.json and a saved basis say which prebo, commit, Python,
    numpy, BLAS, threads, ranks and command line made them."""
    (tmp_path / "h.toml").write_text(H_TOML)
    args = ["run", str(tmp_path / "h.toml"), "--out", str(tmp_path / "out"), "--quiet"]
    with pytest.MonkeyPatch.context() as m:
        m.setattr(sys, "argv", ["prebo", *args])
        assert main(args) == 0
    for name in ("result.json", "basis.json"):
        p = json.loads((tmp_path / "out" / name).read_text())["provenance"]
        assert p["prebo"] == prebo.__version__ and p["commit"] == commit()
        assert p["python"] == platform.python_version() and p["numpy"] == np.__version__
        assert p["threads"] == _core.num_threads() and p["ranks"] == 1 and p["command"] == ["prebo", *args]
        assert all({"library", "version", "threads"} <= set(b) for b in p["blas"])
    basis = prebo.Basis.load(tmp_path / "out" / "basis.json")
    basis.save(tmp_path / "saved.json")
    assert json.loads((tmp_path / "saved.json").read_text())["provenance"]["prebo"] == prebo.__version__


def test_files_without_provenance_load_and_a_malformed_one_is_refused(tmp_path):
    """Stored bases of earlier versions have no provenance and load as before (the same energy);
    a provenance that is not an object is refused, naming the file."""
    stored = ROOT / "examples" / "bases" / "h" / "basis.json"
    d = json.loads(stored.read_text())
    assert "provenance" not in d
    energy = prebo.evaluate(prebo.Basis.load(stored))["energy"]
    d["provenance"] = {"prebo": "0.0.1", "anything": [1, 2]}
    (tmp_path / "with.json").write_text(json.dumps(d))
    assert prebo.evaluate(prebo.Basis.load(tmp_path / "with.json"))["energy"] == energy
    d["provenance"] = "prebo 0.1"
    (tmp_path / "bad.json").write_text(json.dumps(d))
    with pytest.raises(BasisFileError, match=r"bad\.json.*provenance"):
        prebo.Basis.load(tmp_path / "bad.json")
