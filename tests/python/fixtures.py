"""The fixture FMUs of tests/fixtures/fmus, built with gcc and packed into .fmu archives.

Each folder tests/fixtures/fmus/<Name>/ holds modelDescription.xml (modelIdentifier = <Name>),
<Name>.c (the model: three functions over the shared FMI 2.0 co-simulation API in
tests/fixtures/fmus/include/fixture.h) and optionally resources/. `build(name, dest)` compiles the
C file into binaries/linux64/<Name>.so and zips the three into dest/<Name>.fmu.
"""
import pathlib
import shutil
import subprocess
import zipfile

from conftest import ROOT

FIXTURES = ROOT / "tests" / "fixtures" / "fmus"
INCLUDE = FIXTURES / "include"


def names():
    """Every fixture FMU (a folder with a modelDescription.xml)."""
    return sorted(p.parent.name for p in FIXTURES.glob("*/modelDescription.xml"))


def build(name: str, dest: pathlib.Path) -> pathlib.Path:
    """Compiles and packs fixture `name` into dest/<name>.fmu; returns its path."""
    src = FIXTURES / name
    dest = pathlib.Path(dest)
    work = dest / f"{name}.build"
    shutil.rmtree(work, ignore_errors=True)
    so = work / "binaries" / "linux64" / f"{name}.so"
    so.parent.mkdir(parents=True)
    cmd = ["gcc", "-shared", "-fPIC", "-O2", "-std=c99", "-Wall", "-Wextra", "-Werror", "-fvisibility=hidden",
           "-I", str(INCLUDE), "-o", str(so), str(src / f"{name}.c"), "-lm"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"gcc failed for fixture {name}:\n{r.stderr}")
    fmu = dest / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(src / "modelDescription.xml", "modelDescription.xml")
        z.write(so, f"binaries/linux64/{name}.so")
        res = src / "resources"
        if res.is_dir():
            for f in sorted(res.rglob("*")):
                if f.is_file():
                    z.write(f, f"resources/{f.relative_to(res).as_posix()}")
    shutil.rmtree(work)
    return fmu


def build_all(dest: pathlib.Path) -> dict:
    """Every fixture built into dest: {name: path of the .fmu}."""
    return {n: build(n, dest) for n in names()}
