#!/usr/bin/env bash
# Rewrites the guide's generated tables (planners in docs/planners.md, limits in
# docs/scenarios.md, presets in README.md) from the code that owns them:
# `plumetrace planners --markdown`, `plumetrace limits --markdown` and
# `plumetrace presets --markdown`. The CLI tests fail when
# the guide and the code disagree; run this after changing a planner key, a limit or a preset.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bin plumetrace
bin="${CARGO_TARGET_DIR:-target}/release/plumetrace"
python3 - "$bin" <<'PY'
import subprocess, sys
bin = sys.argv[1]
for name, cmd, path in [("planners", ["planners", "--markdown"], "docs/planners.md"),
                        ("limits", ["limits", "--markdown"], "docs/scenarios.md"),
                        ("presets", ["presets", "--markdown"], "README.md")]:
    text = open(path).read()
    md = subprocess.run([bin] + cmd, check=True, capture_output=True, text=True).stdout
    start, end = f"<!-- {name}:start -->\n", f"<!-- {name}:end -->"
    a = text.index(start) + len(start)
    b = text.index(end)
    text = text[:a] + md + text[b:]
    open(path, "w").write(text)
PY
