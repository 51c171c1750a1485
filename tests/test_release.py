"""The release workflow (.github/workflows/release.yml): the maturin action builds an abi3 wheel
for each platform prebo ships (manylinux2014 x86_64 and aarch64, macOS x86_64 and arm64 or
universal2, Windows x86_64) and the sdist; each wheel is installed into a fresh virtual
environment on its own platform and the test suite runs against it; PyPI trusted publishing
comes after all of them."""

import re
from pathlib import Path

import yaml

from prebo.io.toml import tomllib

ROOT = Path(__file__).resolve().parents[1]
MATURIN = "PyO3/maturin-action"
# (OS, architecture) of each wheel, with the manylinux policy the Linux ones must name
WHEELS = {("linux", "x86_64"): "2014", ("linux", "aarch64"): "2014", ("macos", "x86_64"): None,
          ("macos", "aarch64"): None, ("windows", "x86_64"): None}
ARCH = {"x64": "x86_64", "x86_64": "x86_64", "aarch64": "aarch64", "arm64": "aarch64"}


def workflow() -> dict:
    return yaml.safe_load((ROOT / ".github" / "workflows" / "release.yml").read_text())


def expand(value, platform: dict) -> str:
    """`value` with each ${{ matrix.platform.KEY }} (or ${{ matrix.platform.KEY || 'default' }})
    replaced by the platform's entry."""
    pattern = r"\$\{\{\s*matrix\.platform\.(\w+)(?:\s*\|\|\s*'([^']*)')?\s*\}\}"
    return re.sub(pattern, lambda m: str(platform.get(m[1], m[2] or "")), str(value))


def steps(job: dict, action: str) -> list:
    """The steps of `job` that use `action` (any version)."""
    return [s for s in job["steps"] if s.get("uses", "").split("@")[0] == action]


def needs(job: dict) -> set:
    """The jobs `job` waits for."""
    n = job.get("needs", [])
    return {n} if isinstance(n, str) else set(n)


def wheel_jobs(jobs: dict) -> dict:
    """name -> job of the jobs whose maturin step builds wheels over a matrix of platforms."""
    return {name: job for name, job in jobs.items()
            if any(s.get("with", {}).get("command", "build") == "build" for s in steps(job, MATURIN))
            and "platform" in job.get("strategy", {}).get("matrix", {})}


def built(job: dict, platform: dict) -> tuple:
    """(OS, architecture, manylinux policy) of the wheel `job` builds for `platform`."""
    args = {k: expand(v, platform) for k, v in steps(job, MATURIN)[0]["with"].items()}
    os = expand(job["runs-on"], platform).split("-")[0].replace("ubuntu", "linux")
    arch = "universal2" if "universal2" in args.get("target", "") + args.get("args", "") \
        else ARCH[args["target"].split("-")[0]]
    return os, arch, args.get("manylinux")


def test_every_platform_gets_a_release_built_wheel_from_the_maturin_action():
    jobs = workflow()["jobs"]
    found = {}
    for job in wheel_jobs(jobs).values():
        assert "--release" in steps(job, MATURIN)[0]["with"]["args"].split()
        for platform in job["strategy"]["matrix"]["platform"]:
            os, arch, manylinux = built(job, platform)
            for a in (["x86_64", "aarch64"] if arch == "universal2" else [arch]):
                found[os, a] = manylinux if os == "linux" else None
    assert found == WHEELS


def test_an_sdist_is_built_by_the_maturin_action():
    jobs = workflow()["jobs"]
    sdist = [s for job in jobs.values() for s in steps(job, MATURIN) if s["with"]["command"] == "sdist"]
    assert len(sdist) == 1 and "--out dist" in sdist[0]["with"]["args"]


def test_each_wheel_is_installed_into_a_fresh_venv_on_its_own_platform_and_tested():
    jobs = workflow()["jobs"]
    for name, wheel in wheel_jobs(jobs).items():
        upload = steps(wheel, "actions/upload-artifact")[0]["with"]
        testers = [job for job in jobs.values() if name in needs(job)
                   and any("name" in s["with"] for s in steps(job, "actions/download-artifact"))]
        assert len(testers) == 1, f"no single job tests the wheels of {name}"
        tester = testers[0]
        runners = {p["name"]: p["runner"] for p in tester["strategy"]["matrix"]["platform"]}
        for platform in wheel["strategy"]["matrix"]["platform"]:
            tested = dict(platform, runner=runners.get(platform["name"]))
            assert expand(tester["runs-on"], tested) == expand(wheel["runs-on"], platform)
            download = steps(tester, "actions/download-artifact")[0]["with"]
            assert expand(download["name"], tested) == expand(upload["name"], platform)
        run = "\n".join(s.get("run", "") for s in tester["steps"])
        assert "python -m venv" in run and re.search(r"pip install \S*wheel", run)
        # the whole suite, less the slow checks and tests/test_wheel.py (what this job does)
        assert re.search(r'^\s*python -m pytest(\s+-m "not slow and not wheel")?\s*(#.*)?$', run, re.M)


def test_publishing_waits_for_every_build_and_test_and_uses_trusted_publishing():
    jobs = workflow()["jobs"]
    publish = [job for job in jobs.values() if steps(job, "pypa/gh-action-pypi-publish")]
    assert len(publish) == 1
    assert needs(publish[0]) == {name for name, job in jobs.items() if job is not publish[0]}
    assert publish[0]["permissions"]["id-token"] == "write"
    assert "refs/tags/" in publish[0]["if"]


def test_the_abi3_floor_is_the_packages_python_floor():
    """One wheel per platform serves every Python prebo supports, and none it does not."""
    pyo3 = tomllib.loads((ROOT / "crates" / "prebo-py" / "Cargo.toml").read_text())["dependencies"]["pyo3"]
    (abi3,) = [f for f in pyo3["features"] if f.startswith("abi3")]
    requires = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["requires-python"]
    major, minor = re.fullmatch(r">=\s*(\d+)\.(\d+)", requires).groups()
    assert abi3 == f"abi3-py{major}{minor}"
