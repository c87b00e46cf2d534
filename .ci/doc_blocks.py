#!/usr/bin/env python3
"""Runs the command, C and Python blocks of README.md and docs/*.md as a reader would.

Each line of a ```sh block is a command, run from a scratch directory that sees the
repository's fixtures (`cargo run --release --` is the release binary built beforehand; a
`cargo run` with features builds them first). A ```c block is a quick-start fragment: its
`#include` lines stay on top and the rest becomes the body of `main`, compiled with the page's
own gcc line against the static library. A ```python block runs in the given interpreter.
Lines that set up what `.ci/run` sets up itself (apt-get, the virtual environment, maturin,
`cargo test`, the pytest suite) are not run again: they are listed as covered.

    python3 .ci/doc_blocks.py --python target/pyenv/bin/python

Prints one `test result: doc-blocks. N passed; M failed` line; the exit code is 1 on a failure.
"""

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Run elsewhere in .ci/run (the reason is printed).
COVERED = [
    (re.compile(r"^cargo test\b"), "the test steps of .ci/run"),
    (re.compile(r"^apt-get\b"), "the system packages step of .ci/run"),
    (re.compile(r"^python3 -m venv\b"), "the Python package step of .ci/run"),
    (re.compile(r"\bmaturin develop\b"), "the Python package step of .ci/run"),
    (re.compile(r"-m pytest\b"), "the Python package step of .ci/run"),
    (re.compile(r"^cargo build --release -p fibercell-c$"), "the C ABI step of .ci/run"),
    (re.compile(r"^cargo build --release --features mpi$"),
     "the all-features tests of .ci/run (tests/ensemble_mpi.rs runs mpirun -np 2)"),
    (re.compile(r"^mpirun\b"),
     "the all-features tests of .ci/run (tests/ensemble_mpi.rs runs mpirun -np 2)"),
    # The same command as a test: a release build of its own would rebuild the library (2 min).
    (re.compile(r"^cargo run --release --features cholmod -- solve fixtures/ok_frame3d\.toml --solver cholmod$"),
     "the all-features tests of .ci/run (tests/cli.rs solves fixtures/ok_frame3d.toml with --solver cholmod)"),
]


def blocks(path):
    """(language, first line number, lines) of every fenced block of a page."""
    out, lang, start, body = [], None, 0, []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if line.startswith("```"):
                if lang is None:
                    lang, start, body = line[3:].strip(), n + 1, []
                else:
                    out.append((lang, start, body))
                    lang = None
            elif lang is not None:
                body.append(line)
    return out


def command(line):
    """The command of a block line without its trailing comment ('' for none)."""
    line = re.sub(r"\s+#\s.*$", "", line).strip()
    return "" if line.startswith("#") else line


def run(cmd, cwd, label, results):
    print(f"== {label}: {cmd}", flush=True)
    done = subprocess.run(cmd, shell=True, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True)
    tail = "\n".join(done.stdout.strip().splitlines()[-5:])
    if tail:
        print(tail)
    ok = done.returncode == 0
    print(f"   {'ok' if ok else f'FAILED (exit {done.returncode})'}", flush=True)
    results.append(ok)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--python", required=True, help="interpreter with the fibercell package")
    args = parser.parse_args()
    # The blocks run in a scratch directory: the interpreter's path must not be relative.
    python = os.path.abspath(args.python)
    pages = [os.path.join(ROOT, "README.md")] + sorted(
        os.path.join(ROOT, "docs", p) for p in os.listdir(os.path.join(ROOT, "docs")) if p.endswith(".md")
    )
    binary = os.path.join(ROOT, "target", "release", "fibercell")
    results = []
    with tempfile.TemporaryDirectory() as scratch:
        os.symlink(os.path.join(ROOT, "fixtures"), os.path.join(scratch, "fixtures"))
        for page in pages:
            name = os.path.relpath(page, ROOT)
            c_blocks = [b for b in blocks(page) if b[0] == "c"]
            for lang, start, body in blocks(page):
                label = f"{name}:{start}"
                if lang == "sh":
                    for k, line in enumerate(body):
                        cmd = command(line)
                        if not cmd:
                            continue
                        reason = next((r for p, r in COVERED if p.search(cmd)), None)
                        if reason:
                            print(f"== {name}:{start + k}: {cmd}\n   covered by {reason}")
                            continue
                        if cmd.startswith("gcc ") and "prog.c" in cmd:
                            # The page's C quick start, made a program.
                            fragment = c_blocks[0][2] if c_blocks else []
                            includes = [l for l in fragment if l.startswith("#include")]
                            code = [l for l in fragment if not l.startswith("#include")]
                            with open(os.path.join(scratch, "prog.c"), "w") as f:
                                f.write("\n".join(["#include <stdio.h>", *includes,
                                                   "int main(void) {", *code, "return 0;", "}", ""]))
                            cmd = cmd.replace("-I bindings/", f"-I {ROOT}/bindings/").replace(
                                " target/", f" {ROOT}/target/") + " && ./prog"
                        elif cmd.startswith("cargo run --release -- "):
                            cmd = shlex.quote(binary) + cmd[len("cargo run --release --"):]
                        elif cmd.startswith("cargo "):
                            cmd = f"cargo {cmd[len('cargo '):]} --manifest-path {ROOT}/Cargo.toml" \
                                if " -- " not in cmd else cmd.replace(
                                    " -- ", f" --manifest-path {ROOT}/Cargo.toml -- ", 1)
                        run(cmd, scratch, f"{name}:{start + k}", results)
                elif lang == "python":
                    script = os.path.join(scratch, "block.py")
                    with open(script, "w") as f:
                        f.write("\n".join(body) + "\n")
                    run(f"{shlex.quote(python)} block.py", scratch, label, results)
    passed, failed = results.count(True), results.count(False)
    print(f"test result: doc-blocks. {passed} passed; {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
