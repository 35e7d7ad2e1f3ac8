#!/usr/bin/env bash
# Rewrites the README's generated tables (planners, limits) from the code that owns them:
# `plumetrace planners --markdown` and `plumetrace limits --markdown`. The CLI tests fail when
# the README and the code disagree; run this after changing a planner key or a limit.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --quiet --bin plumetrace
bin="${CARGO_TARGET_DIR:-target}/debug/plumetrace"
python3 - "$bin" <<'PY'
import subprocess, sys
bin = sys.argv[1]
text = open("README.md").read()
for name, cmd in [("planners", ["planners", "--markdown"]), ("limits", ["limits", "--markdown"])]:
    md = subprocess.run([bin] + cmd, check=True, capture_output=True, text=True).stdout
    start, end = f"<!-- {name}:start -->\n", f"<!-- {name}:end -->"
    a = text.index(start) + len(start)
    b = text.index(end)
    text = text[:a] + md + text[b:]
open("README.md", "w").write(text)
PY
