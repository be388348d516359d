#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# The include check refuses what it is there to refuse: run on small trees beside the real
# docs/code-overview.md, each with one bad include planted (a feature from the hub, the interpreter
# and the real-time core; a layer reaching up the tables) and one with a table whose arrow points up.
"""usage: include_directions_test.py SOURCE_DIR"""
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

# (file planted, the include it holds, words the refusal must contain)
PLANTED = [
    ("include/opencnc/controller/planted.hpp", "opencnc/edm/edm_codes.hpp",
     "the feature 'edm' is included by 'controller'"),
    ("src/gcode/planted.cpp", "opencnc/broaching/coupling_codes.hpp",
     "the feature 'broaching' is included by 'gcode'"),
    ("include/opencnc/control/planted.hpp", "opencnc/retrace/retrace.hpp",
     "the feature 'retrace' is included by 'control'"),
    ("src/core/planted.cpp", "opencnc/drill/hand_axis.hpp", "the feature 'drill' is included by 'core'"),
    ("include/opencnc/controller/planted.hpp", "opencnc/hmi/server.hpp",
     "includes opencnc/hmi/server.hpp, but layer 'controller' depends only on"),
    ("include/opencnc/analysis/planted.hpp", "opencnc/controller/controller.hpp",
     "includes opencnc/controller/controller.hpp, but layer 'analysis' depends only on"),
    ("src/plan/planted.cpp", "opencnc/gcode/interpreter.hpp",
     "includes opencnc/gcode/interpreter.hpp, but layer 'plan' depends only on"),
]


def run(checker, root):
    p = subprocess.run([sys.executable, str(checker), str(root)], capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def tree(doc_text, planted=None):
    root = Path(tempfile.mkdtemp(prefix="opencnc-include-check-"))
    (root / "docs").mkdir()
    (root / "docs/code-overview.md").write_text(doc_text)
    if planted:
        path, include = planted
        (root / path).parent.mkdir(parents=True)
        (root / path).write_text(f'// planted\n#include "{include}"\n')
    return root


def main():
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        asked = sys.argv[1:2] in (["--help"], ["-h"])
        print(__doc__, file=sys.stdout if asked else sys.stderr)
        return 0 if asked else 2
    source = Path(sys.argv[1])
    checker = Path(__file__).with_name("include_directions.py")
    doc = (source / "docs/code-overview.md").read_text()
    failures = []

    root = tree(doc)
    code, out = run(checker, root)
    shutil.rmtree(root)
    if code != 0:
        failures.append(f"a tree with nothing planted was refused:\n{out}")

    for path, include, words in PLANTED:
        root = tree(doc, (path, include))
        code, out = run(checker, root)
        shutil.rmtree(root)
        if code != 1 or words not in out:
            failures.append(f"{path} including {include}: exit {code}, expected 1 with '{words}':\n{out}")

    # The order of the tables: the analysis row moved below the hub, which depends on it.
    lines = doc.splitlines(keepends=True)
    analysis = next(i for i, l in enumerate(lines) if l.startswith("| `analysis` |"))
    hub = next(i for i, l in enumerate(lines) if l.startswith("| `controller` |"))
    if analysis < hub:
        moved = lines[:analysis] + lines[analysis + 1:hub + 1] + [lines[analysis]] + lines[hub + 1:]
        root = tree("".join(moved))
        code, out = run(checker, root)
        shutil.rmtree(root)
        words = "'controller' depends on 'analysis', which is listed below it"
        if code != 1 or words not in out:
            failures.append(f"a table whose arrow points up: exit {code}, expected 1 with '{words}':\n{out}")
    else:
        failures.append("docs/code-overview.md: the analysis row is not above the hub's")

    for f in failures:
        print(f)
    if failures:
        return 1
    print(f"the include check refuses all {len(PLANTED)} planted includes and a table whose arrow points up")
    return 0


if __name__ == "__main__":
    sys.exit(main())
