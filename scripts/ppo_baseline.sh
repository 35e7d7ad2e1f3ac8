#!/usr/bin/env bash
# The benchmark's learned baseline: PPO (Stable-Baselines3) trained through the vectorised
# Gymnasium environment on the tuning seeds of the coastal task, then flown on its test seeds
# through the Python planner seam (scripts/ppo_baseline.py says how).
#
#   scripts/ppo_baseline.sh            the documented budget: 200,000 environment steps on 4
#                                      copies (373 s on 2 busy cores), then the task's 100 test
#                                      seeds (182 s); into target/ppo
#   scripts/ppo_baseline.sh --tiny     CI: 2,048 steps on 2 copies, 2 test seeds, after the
#                                      Stable-Baselines3 tests of the package (check_env, the
#                                      VecEnv adapter, a short PPO run); into target/ppo-tiny
#
# Makes its environment with scripts/venvs.sh ppo (torch and stable-baselines3, 2.35 GB of
# wheels) and installs the package from the repository into it. Other arguments go to
# scripts/ppo_baseline.py (--timesteps, --envs, --seed, --test-seeds, --out).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"

tiny=0
args=()
for a in "$@"; do
    case "$a" in
        --tiny) tiny=1 ;;
        -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
        *) args+=("$a") ;;
    esac
done

venv=$(bash "$here/venvs.sh" ppo)
start=$SECONDS
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$root/crates/plumetrace-py"
echo "pip install of the package into $venv: $((SECONDS - start)) s"

if [ "$tiny" -eq 1 ]; then
    (cd "$root/crates/plumetrace-py/tests" && "$venv/bin/python" -m pytest -q test_sb3.py)
    "$venv/bin/python" "$here/ppo_baseline.py" --timesteps 2048 --envs 2 --test-seeds 2 \
        --out "$root/target/ppo-tiny" "${args[@]}"
    test -s "$root/target/ppo-tiny/ppo_coastal.zip"
    test -s "$root/target/ppo-tiny/ppo.json"
else
    "$venv/bin/python" "$here/ppo_baseline.py" "${args[@]}"
fi
