#!/usr/bin/env bash
# gryffin_ros's three surrogates (kde, gp, auto) and the GP peers BoTorch and GPyOpt on the peer harness's problems, in
# one run on this machine (two lanes in parallel, one thread each; ask times are process CPU, so the lanes do not skew
# them), then the harness's summary table. Usage, from the project root:
#   benchmarks/peers/side_by_side.sh [OUT]      (default OUT: peer-results; SEEDS and TASKS override the defaults)
# The peers' virtual environments come from ../shared/peers/install_peer.sh (botorch, gpyopt) in /tmp/peervenvs.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
PEERS=${PEERS_DIR:-$ROOT/../shared/peers}
VENVS=${PEERVENVS:-/tmp/peervenvs}
OUT=$(mkdir -p "${1:-$ROOT/peer-results}" && cd "${1:-$ROOT/peer-results}" && pwd)
TASKS=${TASKS:-branin,slope,reactor}
SEEDS=${SEEDS:-branin=0-9,slope=0-9,reactor=0-2}
export OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST

ours() { PEER_PATH="$ROOT/benchmarks/peers" "$ROOT/.venv/bin/python" "$PEERS/harness.py" --peer "$1" \
           --tasks "$TASKS" --seeds "$SEEDS" --out "$OUT"; }
peer() { "$VENVS/$1/bin/python" "$PEERS/harness.py" --peer "$1" --tasks "$TASKS" --seeds "$SEEDS" --out "$OUT"; }

cd "$PEERS"
( ours gryffin_ros_gp; ours gryffin_ros_kde; peer gpyopt ) > "$OUT/lane1.log" 2>&1 &
( peer botorch; ours gryffin_ros_auto ) > "$OUT/lane2.log" 2>&1 &
wait
python3 "$PEERS/aggregate.py" "$OUT"
echo "table: $OUT/summary.md"
