"""Every command line and snippet of README.md, in the README's order and as written, on the build
`cargo xtask test` has just made (FMUs in target/fmu, the master in target/release, the venv
target/venv with the `shipsim` package), from the repository's root, as the README says to run
them (issue 36, items 5, 7 and 8).

- A line of a ```sh block (a line ending in `\\` joined with the next) runs in `bash -c`, and the
  environment it leaves is the next line's: the README's own `export PATH=...` line is what puts
  `shipsim` on PATH (the test starts from a PATH with no `shipsim` on it). A line that is only a
  comment is no command.
- A ```python block runs as a script file with target/venv/bin/python (as the README says), in
  that environment. It may print at most MAX_PYTHON_LINES lines: libcosim's debug log (about 250
  lines without the log level the snippets set) and Dask's "Nanny failed to start" (459 lines in
  a script without `if __name__ == "__main__":`) are far more.
- Other blocks (toml, the layout) are no commands.

Nothing may be written into the source tree: after every step, every file and folder outside
.git and target/ (path, size, mtime) is compared with before the step; only the root-level paths
.gitignore lists (/*.csv, /*.png, /*.ssp, /*.bin, /rrs/, results/, ...) may appear or change. At
the end the test removes the root-level outputs it created; those that existed before (a user's
own run of the README) the same commands overwrite, and a campaign folder under results/ that
exists is resumed, as a user's run would.

What is left out is SKIP below, each with its reason; a SKIP entry that matches no README line
fails the test (so the list follows the README).
"""
import fnmatch
import os
import pathlib
import re
import shutil
import subprocess
import time

import pytest
from conftest import ROOT

PYTHON = ROOT / "target" / "venv" / "bin" / "python"
# A Python snippet prints at most this many lines (stdout and stderr together).
MAX_PYTHON_LINES = 20
# One README step (a command line or a snippet) takes at most this long [s].
STEP_TIMEOUT = 300

# (kind, the start of a command line ("sh") or a text in a block ("python"), why it does not run
# here). The first matching entry applies.
SKIP = [
    ("sh", "cargo xtask test", "this test runs inside it"),
    ("sh", "cargo xtask build-fmus --platforms linux64",
     "would replace target/fmu's FMUs by linux64-only ones, and test_win64.py runs their "
     "win64 binaries after this test"),
    ("sh", "cargo xtask build-fmus",
     "a cargo build that `cargo xtask test` has just made (its first step; issue 36, item 4)"),
    ("sh", "cargo xtask report",
     "runs every study of tests/src/studies: long (the system tests of `cargo xtask test` "
     "run them)"),
    ("sh", "cargo xtask export-osp",
     "a cargo build (issue 36, item 4); the export it makes per system is the README's "
     "`shipsim export-osp systems/rrs.toml -o target/osp/rrs/...` line"),
    ("sh", "cargo xtask bench", "a benchmark: long, and its own figures (docs/bench.md)"),
    ("sh", "cargo xtask wheel",
     "a maturin release build of the extension (minutes); `cargo xtask test` has just built "
     "and installed the same package into the venv"),
    ("sh", "cargo xtask artifacts",
     "builds and runs every FMU, system and study, or compares two such folders: long"),
    ("sh", "cargo xtask lint",
     "clippy over the workspace (minutes); `cargo xtask test` runs it itself"),
    ("sh", "python3 master/bench/bench_instructions.py",
     "a benchmark of two builds (OLD/, NEW/ are placeholders) under valgrind"),
    ("sh", "cargo xtask export-ssp",
     "a cargo build (issue 36, item 4); the README's `shipsim export-ssp systems/rrs.toml "
     "-o rrs.ssp` line makes the same export of one system"),
    ("sh", "shipsim campaign run  campaigns/rrs_polar.toml --shard",
     "one shard of a cluster array job (Slurm, k8s) into out/3"),
    ("sh", "shipsim campaign merge out/*", "merges the shards of that cluster array job"),
    ("sh", "pip install",
     "builds the extension from source (minutes) and would replace the package under test; "
     "`cargo xtask test` has just installed it this way (pip install ./python)"),
    ("sh", "dask scheduler", "a server: runs until stopped"),
    ("sh", "dask worker", "a cluster worker: runs until stopped, needs the scheduler"),
    ("python", 'client=Client("tcp://HEAD:8786")',
     "a cluster (HEAD) and a shared file system (/shared/ship); the LocalCluster block after "
     "it makes the same call on one machine"),
]


def readme_steps():
    """[(kind, text, README line number)] in the README's order: kind "sh" (one command line) or
    "python" (one block)."""
    text = (ROOT / "README.md").read_text()
    steps = []
    for m in re.finditer(r"^```(\w*)\n(.*?)^```", text, re.S | re.M):
        lang, body = m.group(1), m.group(2)
        first = text.count("\n", 0, m.start(2)) + 1
        if lang == "python":
            steps.append(("python", body, first))
        elif lang == "sh":
            lines = body.splitlines()
            i = 0
            while i < len(lines):
                line, number = lines[i], first + i
                while line.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    line = line + "\n" + lines[i]
                i += 1
                if line.strip() and not line.lstrip().startswith("#"):
                    steps.append(("sh", line.strip(), number))
    return steps


def skip_reason(kind, text, used):
    for i, (skip_kind, key, reason) in enumerate(SKIP):
        if kind == skip_kind and (text.startswith(key) if kind == "sh" else key in text):
            used.add(i)
            return reason
    return None


def root_patterns():
    """The .gitignore patterns that may match a path at the repository's root."""
    patterns = []
    for line in (ROOT / ".gitignore").read_text().splitlines():
        line = line.strip()
        if line and not line.startswith(("#", "!")) and "/" not in line.strip("/"):
            patterns.append(line.strip("/"))
    return patterns


def is_root_output(name, patterns):
    return any(fnmatch.fnmatch(name, p) for p in patterns)


def source_tree(patterns):
    """{path: (size, mtime_ns)} of every file and folder outside .git, target/ and the ignored
    root-level outputs (and __pycache__ folders, which Python writes where it imports from)."""
    tree = {}
    for top, dirs, files in os.walk(ROOT):
        rel = pathlib.Path(top).relative_to(ROOT)
        if rel == pathlib.Path("."):
            dirs[:] = [d for d in dirs if d != ".git" and not is_root_output(d, patterns)]
            files = [f for f in files if not is_root_output(f, patterns)]
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in dirs + files:
            st = os.lstat(os.path.join(top, name))
            tree[str(rel / name)] = (st.st_size if name in files else -1, st.st_mtime_ns)
    return tree


def root_outputs(patterns):
    """The ignored root-level outputs (not target/) and, for folders, their entries."""
    found = set()
    for entry in ROOT.iterdir():
        if entry.name != "target" and is_root_output(entry.name, patterns):
            found.add(entry.name)
            if entry.is_dir() and not entry.is_symlink():
                found.update(f"{entry.name}/{c.name}" for c in entry.iterdir())
    return found


def remove_new_outputs(before, patterns):
    for rel in sorted(root_outputs(patterns) - before):
        path = ROOT / rel
        if "/" in rel and rel.split("/")[0] not in before:
            continue  # inside a new folder, which goes as a whole
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()


def start_env():
    """This process's environment without any `shipsim` on PATH: the README's `export PATH=...`
    line must put it there."""
    env = dict(os.environ)
    dirs = env.get("PATH", "").split(os.pathsep)
    env["PATH"] = os.pathsep.join(
        d for d in dirs if d and not os.path.exists(os.path.join(d, "shipsim")))
    env["PWD"] = str(ROOT)
    return env


def run_sh(line, env, tmp_path):
    """Runs one command line in bash from the root; returns its output and the environment it
    leaves (for the next line)."""
    env_file = tmp_path / "env"
    script = f"{line}\n__readme_rc=$?\nenv -0 > '{env_file}'\nexit $__readme_rc\n"
    r = subprocess.run(["bash", "-c", script], cwd=ROOT, env=env, stdin=subprocess.DEVNULL,
                       capture_output=True, text=True, timeout=STEP_TIMEOUT)
    out = r.stdout + r.stderr
    assert r.returncode == 0, f"exit status {r.returncode}:\n{out[-4000:]}"
    pairs = (item.split("=", 1) for item in env_file.read_text().split("\0") if "=" in item)
    return out, {k: v for k, v in pairs if not k.startswith("__readme") and k not in ("_", "SHLVL")}


def run_python(code, env, tmp_path, number):
    script = tmp_path / f"readme_line_{number}.py"
    script.write_text(code)
    r = subprocess.run([str(PYTHON), str(script)], cwd=ROOT, env=env, stdin=subprocess.DEVNULL,
                       capture_output=True, text=True, timeout=STEP_TIMEOUT)
    out = r.stdout + r.stderr
    lines = out.splitlines()
    assert r.returncode == 0, f"exit status {r.returncode}:\n" + "\n".join(lines[-40:])
    assert len(lines) <= MAX_PYTHON_LINES, (
        f"{len(lines)} lines of output (at most {MAX_PYTHON_LINES}):\n" + "\n".join(lines[:40]))
    return out


def test_readme_runs_in_order_without_writing_into_the_source_tree(tmp_path):
    for path, what in ((PYTHON, "the venv"),
                       (ROOT / "target" / "release" / "shipsim", "the master"),
                       (ROOT / "target" / "fmu" / "SteeringGear.fmu", "the FMUs")):
        if not path.exists():
            pytest.fail(f"{path} is missing ({what}): run `cargo xtask test`", pytrace=False)
    steps = readme_steps()
    assert any(kind == "python" for kind, _, _ in steps) and len(steps) > 30, steps
    used, skipped, timings = set(), [], []
    patterns = root_patterns()
    outputs_before = root_outputs(patterns)
    env = start_env()
    started = time.monotonic()
    try:
        for kind, text, number in steps:
            reason = skip_reason(kind, text, used)
            if reason is not None:
                skipped.append((number, text.splitlines()[0][:60], reason))
                continue
            tree = source_tree(patterns)
            t0 = time.monotonic()
            try:
                if kind == "sh":
                    out, env = run_sh(text, env, tmp_path)
                    if text.startswith("cargo xtask demo"):
                        # After `cargo xtask test`, the demo shares its build (issue 36, item
                        # 4: it recompiled the 25 FMU crates and the system tests).
                        rebuilt = re.findall(r"Compiling (?:fmu-|system-tests|shipsim)\S*", out)
                        assert not rebuilt, f"the demo rebuilt what the test had built: {rebuilt}"
                else:
                    run_python(text, env, tmp_path, number)
            except AssertionError as e:
                raise AssertionError(f"README.md:{number}: {text}\n{e}") from None
            timings.append((time.monotonic() - t0, number, text.splitlines()[0][:70]))
            after = source_tree(patterns)
            changed = sorted(p for p in set(tree) | set(after) if tree.get(p) != after.get(p))
            assert not changed, (f"README.md:{number}: {text}\nwrote into the source tree "
                                 f"(not an ignored root-level output): {changed}")
    finally:
        remove_new_outputs(outputs_before, patterns)
    unused = [key for i, (_, key, _) in enumerate(SKIP) if i not in used]
    assert not unused, f"SKIP entries that match no README line (remove them): {unused}"
    total = time.monotonic() - started
    print(f"\nREADME: {len(timings)} steps ran in {total:.0f} s; slowest:")
    for seconds, number, line in sorted(timings, reverse=True)[:5]:
        print(f"  {seconds:6.1f} s  README.md:{number}: {line}")
    print(f"left out ({len(skipped)}):")
    for number, line, reason in skipped:
        print(f"  README.md:{number}: {line}: {reason}")
