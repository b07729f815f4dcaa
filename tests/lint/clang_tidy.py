#!/usr/bin/env python3
"""Runs clang-tidy with the checks of .clang-tidy over the C++ sources of libs/, services/ and tools/,
from a build's compile commands; any warning fails. Usage:

    tests/lint/clang_tidy.py BUILD_DIR [FILE...]      (default: every source of those folders)

A source found clean is not checked again while its preprocessed text (every header it includes,
paths taken relative to the source root), its compile flags, .clang-tidy and clang-tidy's version
are unchanged: the check set costs about 9 CPU-minutes over the whole tree here, and a change
touches a few sources. Clean results are remembered in $XDG_CACHE_HOME/evldt-clang-tidy (or
~/.cache/...), outside any clone, as ccache keeps compilations."""
import concurrent.futures
import hashlib
import json
import os
import pathlib
import shlex
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
FOLDERS = ("libs/", "services/", "tools/")


def tidy_version():
    return subprocess.run(["clang-tidy", "--version"], capture_output=True, text=True, check=True).stdout


def preprocess_command(command):
    """The compile command with its output and launcher replaced: preprocess to stdout."""
    args = shlex.split(command)
    if pathlib.Path(args[0]).name == "ccache":
        args = args[1:]
    out = []
    skip = False
    for arg in args:
        if skip:
            skip = False
            continue
        if arg in ("-o", "-MF", "-MT"):
            skip = True
            continue
        if arg in ("-c", "-MD"):
            continue
        out.append(arg)
    return out + ["-E"]


def cache_key(entry, salt):
    root = str(ROOT)
    pre = subprocess.run(preprocess_command(entry["command"]), cwd=entry["directory"], capture_output=True, check=False)
    if pre.returncode != 0:
        return None  # let clang-tidy report it
    digest = hashlib.sha256(salt)
    digest.update(entry["command"].replace(root, "").encode())
    digest.update(pre.stdout.replace(root.encode(), b""))
    return digest.hexdigest()


def check(entry, build, cache, salt):
    source = os.path.relpath(entry["file"], ROOT)
    key = cache_key(entry, salt)
    if key and (cache / key).exists():
        return source, True, "", True
    run = subprocess.run(["clang-tidy", "-p", str(build), "--quiet", "--warnings-as-errors=*", entry["file"]],
                         capture_output=True, text=True, check=False)
    clean = run.returncode == 0 and "warning:" not in run.stdout
    if clean and key:
        (cache / key).touch()
    return source, clean, run.stdout, False


def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    build = pathlib.Path(sys.argv[1]).resolve()
    database = build / "compile_commands.json"
    if not database.exists():
        print(f"clang_tidy: no {database}: configure the build first", file=sys.stderr)
        return 2
    wanted = {str((ROOT / f).resolve()) for f in sys.argv[2:]}
    entries = []
    for entry in json.loads(database.read_text()):
        source = os.path.relpath(entry["file"], ROOT)
        if source.startswith(FOLDERS) and (not wanted or entry["file"] in wanted):
            entries.append(entry)
    cache = pathlib.Path(os.environ.get("XDG_CACHE_HOME", pathlib.Path.home() / ".cache")) / "evldt-clang-tidy"
    cache.mkdir(parents=True, exist_ok=True)
    salt = (tidy_version() + (ROOT / ".clang-tidy").read_text()).encode()
    failed = []
    remembered = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        for source, clean, output, cached in pool.map(lambda e: check(e, build, cache, salt), entries):
            remembered += cached
            if not clean:
                failed.append(source)
                print(output, end="")
    print(f"clang-tidy: {len(entries)} sources, {remembered} clean before and unchanged, {len(failed)} with warnings")
    for source in failed:
        print(f"  {source}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
