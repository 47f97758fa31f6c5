#!/usr/bin/env python3
"""Compiles each source file under the given folders alone, syntax only.

    .ci/compile_alone.py BUILD_DIR ROOT FOLDER...

BUILD_DIR was configured with CMAKE_UNITY_BUILD=OFF and CMAKE_EXPORT_COMPILE_COMMANDS=ON. Runs
every compile command whose file lies under ROOT/FOLDER with -fsyntax-only instead of its
output, two at a time; prints each failure's diagnostics and exits 1 if any failed.
"""
import concurrent.futures
import json
import os
import shlex
import subprocess
import sys


def syntax_only(entry):
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    kept, skip = [], False
    for arg in args:
        if skip:
            skip = False
        elif arg == "-o":
            skip = True  # and its object file
        else:
            kept.append(arg)
    run = subprocess.run(kept + ["-fsyntax-only"], cwd=entry["directory"], capture_output=True, text=True)
    return entry["file"], run.returncode, run.stdout + run.stderr


def main(argv):
    if len(argv) < 4:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    with open(os.path.join(argv[1], "compile_commands.json"), encoding="utf-8") as f:
        commands = json.load(f)
    folders = tuple(os.path.join(os.path.abspath(argv[2]), d) + os.sep for d in argv[3:])
    chosen = [c for c in commands if os.path.abspath(c["file"]).startswith(folders)]
    if not chosen:
        print("compile-alone: no compile command under %s" % ", ".join(argv[3:]), file=sys.stderr)
        return 1
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=int(os.environ.get("JOBS", "2"))) as pool:
        for path, code, output in pool.map(syntax_only, chosen):
            if code != 0:
                failed += 1
                print("compile-alone: %s does not compile alone:\n%s" % (path, output), file=sys.stderr)
    print("compile-alone: %d files, %d failed" % (len(chosen), failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
