#!/usr/bin/env bash
# The Python virtual environments the checks use, made or brought up to date in one place:
#   fuzzy    scripts/.venv-fuzzy   scikit-fuzzy 0.5.0 and what it imports (fuzzy_crosscheck.sh)
#   netcdf   scripts/.venv-netcdf  numpy, scipy and xarray (netcdf_check.sh)
#   package  target/py-venv        maturin, Gymnasium, pytest and the package's optional
#                                  dependencies (python_tests.sh)
#   ppo      target/ppo-venv       torch and stable-baselines3 for the PPO baseline (ppo_baseline.sh):
#            torch from PyPI without the CUDA packages it does not load on a CPU (triton,
#            cuSOLVER, the CUDA Python bindings): 2.35 GB of wheels instead of 2.88 GB, 4.2 GB
#            installed instead of 5.5 GB; not in `all` (CI installs it in a step of its own)
#   all      the three (fuzzy, netcdf, package)
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
        package) echo "numpy maturin==1.16.0 gymnasium==1.4.0 pytest>=7 pandas pyarrow tqdm dask[distributed] matplotlib xarray scipy" ;;
        ppo) echo "$PPO_NO_DEPS $PPO_DEPS" ;;
        *) return 1 ;;
    esac
}

# torch's wheel on PyPI names every CUDA package as a dependency; a CPU-only run loads the
# libraries below (torch links them) and none of the rest, so they are installed without
# dependencies, then what torch and stable-baselines3 import besides (pip then lists the CUDA
# packages left out as "dependency conflicts": expected, and the install succeeds).
PPO_NO_DEPS="torch==2.15.0 stable-baselines3==2.9.2 nvidia-cuda-runtime==13.2.86 nvidia-cuda-cupti==13.2.86 nvidia-cublas==13.4.1.3 nvidia-cufft==12.2.0.57 nvidia-cufile==1.17.1.22 nvidia-cusparse==12.7.10.12 nvidia-nvjitlink==13.5.37 nvidia-cuda-nvrtc==13.2.86 nvidia-cudnn-cu13==9.26.0.51 nvidia-cusparselt-cu13==0.8.1 nvidia-nccl-cu13==2.30.7 nvidia-nvshmem-cu13==3.7.2"
PPO_DEPS="numpy gymnasium==1.4.0 cloudpickle filelock typing-extensions sympy networkx jinja2 fsspec setuptools>=77 maturin==1.16.0 pytest>=7"

path_of() {
    case "$1" in
        fuzzy) echo "$here/.venv-fuzzy" ;;
        netcdf) echo "$here/.venv-netcdf" ;;
        package) echo "$root/target/py-venv" ;;
        ppo) echo "$root/target/ppo-venv" ;;
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
    if [ "$name" = ppo ]; then
        # shellcheck disable=SC2086 # the lists are words
        "$venv/bin/pip" install --quiet --no-deps $PPO_NO_DEPS
        # shellcheck disable=SC2086
        "$venv/bin/pip" install --quiet $PPO_DEPS
    else
    # shellcheck disable=SC2086 # the list is words
    "$venv/bin/pip" install --quiet $list
    fi
    echo "$list" > "$venv/.plumetrace-packages"
    echo "$venv"
}

if [ $# -eq 0 ]; then
    echo "usage: scripts/venvs.sh NAME... (fuzzy, netcdf, package, ppo or all)" >&2
    exit 2
fi
for name in "$@"; do
    if [ "$name" = all ]; then
        for n in fuzzy netcdf package; do make_venv "$n"; done
    elif packages "$name" >/dev/null; then
        make_venv "$name"
    else
        echo "scripts/venvs.sh: unknown environment '$name' (fuzzy, netcdf, package, ppo or all)" >&2
        exit 2
    fi
done
