#!/usr/bin/env bash
# The Python virtual environments the checks use, made or brought up to date in one place:
#   fuzzy    scripts/.venv-fuzzy   scikit-fuzzy 0.5.0 and what it imports (fuzzy_crosscheck.sh)
#   netcdf   scripts/.venv-netcdf  numpy, scipy and xarray (netcdf_check.sh)
#   package  target/py-venv        maturin, Gymnasium, pytest and the package's optional
#                                  dependencies (python_tests.sh)
#   all      the three
# A stamp file in each environment holds its package list; an environment whose list is
# unchanged is left as it is, so `.ci/run` installs (downloads) everything first, in a step of its
# own, and the checks that use the environments start at once. Prints each environment's path.
#
# Usage: scripts/venvs.sh NAME...
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)

packages() {
    case "$1" in
        fuzzy) echo "scikit-fuzzy==0.5.0 numpy scipy networkx packaging" ;;
        netcdf) echo "numpy scipy xarray" ;;
        package) echo "numpy maturin==1.16.0 gymnasium==1.4.0 pytest>=7 pandas pyarrow tqdm dask[distributed] matplotlib" ;;
        *) return 1 ;;
    esac
}

path_of() {
    case "$1" in
        fuzzy) echo "$here/.venv-fuzzy" ;;
        netcdf) echo "$here/.venv-netcdf" ;;
        package) echo "$root/target/py-venv" ;;
    esac
}

make_venv() {
    local name=$1 venv list
    venv=$(path_of "$name")
    list=$(packages "$name")
    if [ -x "$venv/bin/python" ] && [ "$(cat "$venv/.plumetrace-packages" 2>/dev/null)" = "$list" ]; then
        echo "$venv"
        return
    fi
    rm -rf "$venv"
    python3 -m venv "$venv"
    # Keep the environment out of git, as Python 3.13's venv does by itself.
    printf '*\n' > "$venv/.gitignore"
    # shellcheck disable=SC2086 # the list is words
    "$venv/bin/pip" install --quiet $list
    echo "$list" > "$venv/.plumetrace-packages"
    echo "$venv"
}

if [ $# -eq 0 ]; then
    echo "usage: scripts/venvs.sh NAME... (fuzzy, netcdf, package or all)" >&2
    exit 2
fi
for name in "$@"; do
    if [ "$name" = all ]; then
        for n in fuzzy netcdf package; do make_venv "$n"; done
    elif packages "$name" >/dev/null; then
        make_venv "$name"
    else
        echo "scripts/venvs.sh: unknown environment '$name' (fuzzy, netcdf, package or all)" >&2
        exit 2
    fi
done
