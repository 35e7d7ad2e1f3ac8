#!/usr/bin/env bash
# Runs every shell command of README.md, in order, as a new user would: the indented command
# blocks (lines of four spaces then `cargo ` or `plumetrace `). `cargo install` installs into
# target/readme-root (so the machine's ~/.cargo/bin is left alone) and the installed `plumetrace`
# is the one the later commands run. `cargo test --release --workspace` is skipped (CI runs it on its own).
# Outputs go to a scratch directory, which is removed at the end.
#
# Usage: scripts/readme_commands.sh [--list]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

mapfile -t cmds < <(sed -n 's/^    \(\(cargo\|plumetrace\) .*\)$/\1/p' README.md)
if [ "${#cmds[@]}" -eq 0 ]; then
    echo "readme_commands.sh: README.md has no command lines" >&2
    exit 1
fi
if [ "${1:-}" = "--list" ]; then
    printf '%s\n' "${cmds[@]}"
    exit 0
fi

export CARGO_INSTALL_ROOT="$root/target/readme-root"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
export PATH="$CARGO_INSTALL_ROOT/bin:$PATH"
scratch="$root/target/readme-scratch"
rm -rf "$scratch"
mkdir -p "$scratch"
# `plumetrace` commands run in the scratch directory (with the examples they name), so their
# `out/...` lands there; `cargo` commands run in the repository root, and an `out/` they make
# there is removed afterwards unless it was there before.
ln -s "$root/examples" "$scratch/examples"
had_out=0
if [ -e "$root/out" ]; then had_out=1; fi

n=0
for c in "${cmds[@]}"; do
    case "$c" in
        "cargo test --release --workspace"*) echo "== (skipped: CI runs it) $c"; continue ;;
    esac
    n=$((n + 1))
    echo "== $c"
    start=$SECONDS
    case "$c" in
        cargo*) bash -c "$c" ;;
        *) (cd "$scratch" && bash -c "$c") ;;
    esac
    echo "   ($((SECONDS - start)) s)"
done
if ! command -v plumetrace >/dev/null 2>&1; then
    echo "readme_commands.sh: after the README's commands, plumetrace is not on the PATH" >&2
    exit 1
fi
rm -rf "$scratch"
if [ "$had_out" -eq 0 ]; then rm -rf "$root/out"; fi
echo "README.md: $n commands ran"
