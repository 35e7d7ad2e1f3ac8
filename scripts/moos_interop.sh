#!/usr/bin/env bash
# The MOOS link against a real MOOSDB: starts MOOSDB on a free port with a mission file of its
# own, leaves stale navigation stored in it, flies `plumetrace onboard` (built with the moos
# feature) against a simulated vehicle (scripts/moos_vehicle.py, a MOOS client in Python's
# standard library) after a posting over 1 MiB, checks what the planner publishes, cuts the
# client's connection once (through a relay, the MOOSDB up) and restarts the MOOSDB once and
# checks that the client reconnects and goes on, then prints PASS or FAIL per check. Exits 1 on
# any failure; says it skipped (and exits 0) when there is no MOOSDB on the PATH.
#
#   scripts/moos_interop.sh [--bin PATH] [--keep]
#
# --bin: a plumetrace binary built with `--features moos` (default: build one with cargo into
# the target directory); --keep: keep the working directory (mission file, onboard file and
# output, every process's log) and print its path.
#
# The clients connect over loopback. MOOSDB has no option to listen on one address only: a stock
# build listens on every interface (on a free port, for the 40 s the script takes); the script
# says which address it listens on.
set -euo pipefail
cd "$(dirname "$0")/.."

# The arguments first: a mistyped one is named even where the run would be skipped.
BIN=""
KEEP=0
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) BIN="${2:?--bin needs a path}"; shift 2 ;;
        --keep) KEEP=1; shift ;;
        *) echo "moos_interop: unknown argument '$1' (expected --bin PATH or --keep)" >&2; exit 2 ;;
    esac
done

if ! command -v MOOSDB >/dev/null 2>&1; then
    echo "moos_interop: skipped: no MOOSDB on the PATH (install MOOS-IvP or core-moos to run it)"
    exit 0
fi

if ! command -v python3 >/dev/null 2>&1; then
    echo "moos_interop: FAIL: python3 is needed for the simulated vehicle (scripts/moos_vehicle.py)"
    exit 1
fi

if [ -z "$BIN" ]; then
    echo "moos_interop: building plumetrace with the moos feature (release)"
    cargo build --release --quiet -p plumetrace-cli --features moos
    BIN="${CARGO_TARGET_DIR:-target}/release/plumetrace"
fi
if [ ! -x "$BIN" ]; then
    echo "moos_interop: FAIL: no plumetrace binary at $BIN"
    exit 1
fi

# Timing, in seconds from the start of the vehicle (about a second after the onboard process).
TIME_LIMIT=32        # the onboard run's time limit (from its own start)
OVERRIDE_AT=9        # the vehicle posts MOOS_MANUAL_OVERRIDE = true, and false 3 s later
DB_DOWN_AT=18        # the MOOSDB is stopped ...
DB_DOWN_FOR=2        # ... and started again this much later on the same port
CUT_AT=11            # the relay between the client and the MOOSDB cuts the connection (paused)
COMMUNITY=plumetrace_interop
CONSOLIDATION_MS=150 # the MOOSDB asks pPlumetrace for this much between its packets (--response)

WORK="$(mktemp -d "${TMPDIR:-/tmp}/moos-interop.XXXXXX")"
DB_PID=""
VEHICLE_PID=""
ONBOARD_PID=""
PROXY_PID=""
stop() {
    local pid
    for pid in "$ONBOARD_PID" "$VEHICLE_PID" "$PROXY_PID" "$DB_PID"; do
        if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
            kill "$pid" 2>/dev/null || true
            wait "$pid" 2>/dev/null || true
        fi
    done
}
cleanup() {
    stop
    if [ "$KEEP" = 1 ]; then
        echo "moos_interop: files kept in $WORK"
    else
        rm -rf "$WORK"
    fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
PORT="$(free_port)"
AUDIT_PORT="$(free_port)"
PROXY_PORT="$(free_port)"

cat > "$WORK/interop.moos" <<EOF
// Written by scripts/moos_interop.sh: a community of its own on a free port.
ServerHost = 127.0.0.1
ServerPort = $PORT
Community  = $COMMUNITY
MOOSTimeWarp = 1
LatOrigin  = 43.8253
LongOrigin = -70.3304
EOF

cat > "$WORK/onboard.toml" <<EOF
name = "MOOS interoperability"
[mission]
op_area = [[0.0, -100.0], [300.0, -100.0], [300.0, 100.0], [0.0, 100.0]]
subregions = []
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
lambda_s = 1.0
[link]
protocol = "moos"
origin = { lat_deg = 43.8253, lon_deg = -70.3304 }
stale_nav_s = 2.0
silence_timeout_s = 3.0
reconnect_min_s = 0.1
reconnect_max_s = 1.0
give_up_s = 20.0
[link.moos]
host = "127.0.0.1"
port = $PROXY_PORT
app_name = "pPlumetrace"
chem_variable = "CHEM_READING"
[run]
mode = "real_time"
time_limit_s = $TIME_LIMIT
EOF

start_db() {
    (cd "$WORK" && exec MOOSDB interop.moos --moos_port="$PORT" --audit_port="$AUDIT_PORT" \
        --response="pPlumetrace:$CONSOLIDATION_MS" --moos_suicide_disable --moos_no_colour) \
        >> "$WORK/moosdb.log" 2>&1 &
    DB_PID=$!
    # Ready when it accepts a connection (the probe shows in its log as a failed handshake).
    for _ in $(seq 100); do
        if python3 -c "import socket, sys; socket.create_connection(('127.0.0.1', $PORT), 0.2).close()" 2>/dev/null; then
            return 0
        fi
        if ! kill -0 "$DB_PID" 2>/dev/null; then break; fi
        sleep 0.1
    done
    echo "moos_interop: FAIL: MOOSDB did not listen on port $PORT; its log:"
    tail -n 20 "$WORK/moosdb.log"
    exit 1
}

echo "moos_interop: MOOSDB ($(command -v MOOSDB)) on 127.0.0.1:$PORT, community $COMMUNITY, in $WORK"
start_db
LISTEN="$(python3 - "$PORT" <<'PY' 2>/dev/null || true
import sys
port = int(sys.argv[1])
for line in open("/proc/net/tcp").readlines()[1:]:
    local, state = line.split()[1], line.split()[3]
    addr, p = local.split(":")
    if state == "0A" and int(p, 16) == port:
        print(".".join(str(int(addr[i:i + 2], 16)) for i in (6, 4, 2, 0)))
PY
)"
echo "moos_interop: the MOOSDB listens on ${LISTEN:-?}:$PORT$([ "$LISTEN" = 0.0.0.0 ] && echo ' (every interface)')"
# Stored values a client is sent at registration, however old: navigation of another vehicle,
# posted 50 s ago.
python3 scripts/moos_vehicle.py --port "$PORT" --log /dev/null --prime stale --name uOldVehicle \
    2>> "$WORK/vehicle.log"
# The client reaches the MOOSDB through a relay that cuts its connection once, during the
# override's pause, while the MOOSDB stays up (CPT_PAUSED must still end false).
python3 scripts/moos_vehicle.py --port "$PORT" --log /dev/null --proxy "$PROXY_PORT" \
    --duration $((TIME_LIMIT + 40)) 2>> "$WORK/vehicle.log" &
PROXY_PID=$!
for _ in $(seq 100); do
    if python3 -c "import socket; socket.create_connection(('127.0.0.1', $PROXY_PORT), 0.2).close()" 2>/dev/null; then
        break
    fi
    sleep 0.1
done
"$BIN" onboard "$WORK/onboard.toml" --out "$WORK/onboard-out" > "$WORK/onboard.log" 2>&1 &
ONBOARD_PID=$!
# A second later, once it has registered: a posting over 1 MiB on a variable it reads; then the
# vehicle.
sleep 1 &
wait $!
python3 scripts/moos_vehicle.py --port "$PORT" --log /dev/null --prime huge --name uBigPoster \
    2>> "$WORK/vehicle.log"
python3 scripts/moos_vehicle.py --port "$PORT" --log "$WORK/vehicle.tsv" \
    --duration $((TIME_LIMIT + 15)) --start-x 110 --override-at "$OVERRIDE_AT" \
    --override-for 3 2>> "$WORK/vehicle.log" &
VEHICLE_PID=$!

# Waits up to $1 s, less if the onboard process ends first (in the background, so a signal is
# taken at once).
wait_onboard() {
    local until=$((SECONDS + $1))
    while [ "$SECONDS" -lt "$until" ] && kill -0 "$ONBOARD_PID" 2>/dev/null; do
        sleep 0.2 &
        wait $!
    done
}
wait_onboard "$CUT_AT"
kill -USR1 "$PROXY_PID" 2>/dev/null || true
wait_onboard $((DB_DOWN_AT - CUT_AT))
if kill -0 "$ONBOARD_PID" 2>/dev/null; then
    echo "moos_interop: stopping the MOOSDB for ${DB_DOWN_FOR} s"
    kill "$DB_PID" 2>/dev/null || true
    wait "$DB_PID" 2>/dev/null || true
    sleep "$DB_DOWN_FOR" &
    wait $!
    start_db
    echo "moos_interop: the MOOSDB is back"
fi

# It ends at its time limit; one that has not ended well after it is stopped (and fails).
wait_onboard $((TIME_LIMIT + 30))
if kill -0 "$ONBOARD_PID" 2>/dev/null; then
    echo "moos_interop: the onboard process had not ended well after its time limit: stopping it"
    kill "$ONBOARD_PID" 2>/dev/null || true
fi
ONBOARD_RC=0
wait "$ONBOARD_PID" || ONBOARD_RC=$?
ONBOARD_PID=""
# Let the last postings reach the vehicle, then stop it and the MOOSDB.
sleep 1 &
wait $!
stop

# ---- The checks --------------------------------------------------------------------------------
FAILED=0
PASSED=0
check() { # name, condition (0 passes), detail
    if [ "$2" = 0 ]; then
        PASSED=$((PASSED + 1))
        printf 'PASS  %-16s %s\n' "$1" "$3"
    else
        FAILED=$((FAILED + 1))
        printf 'FAIL  %-16s %s\n' "$1" "$3"
    fi
}
ok() { if "$@"; then echo 0; else echo 1; fi; }
TSV="$WORK/vehicle.tsv"
touch "$TSV"
LINKLOG="$WORK/onboard-out/link.log"
REPORT="$WORK/onboard-out/onboard.json"
# postings KEY [CONNECTION]: the values the vehicle received from pPlumetrace.
postings() {
    awk -F'\t' -v k="$1" -v c="${2:-}" '$3 == k && $4 == "pPlumetrace" && (c == "" || $2 == c) { print $5 }' "$TSV"
}
count() { postings "$@" | wc -l | tr -d ' '; }
# in_range KEY LO HI: every value of KEY is a number in [LO, HI].
in_range() {
    postings "$1" | awk -v lo="$2" -v hi="$3" '{ if (!($1 + 0 >= lo && $1 + 0 <= hi) || $1 !~ /^-?[0-9]/) bad++ } END { exit bad > 0 }'
}
report() { # a field of onboard.json
    python3 -c "import json, sys; print(json.load(open(sys.argv[1])).get(sys.argv[2]))" "$REPORT" "$1" 2>/dev/null || echo "?"
}

END="$(report end)"
check "onboard run" "$(ok test "$ONBOARD_RC" = 0 -a "$END" = timelimit)" \
    "exit $ONBOARD_RC, end $END after $(report time_s) s, $(report nav_records) navigation records, $(report decisions) decisions"
WELCOMES="$(grep -c "welcome to community $COMMUNITY" "$LINKLOG" 2>/dev/null || true)"
WELCOME="$(grep -m1 -o "welcome to community $COMMUNITY.*" "$LINKLOG" 2>/dev/null || true)"
check "handshake" "$(ok test "${WELCOMES:-0}" -ge 1)" "link.log: ${WELCOME:-no welcome}"
REJECTED="$(report lines_rejected)"
check "traffic" "$(ok python3 -c "import json, sys; r = json.load(open(sys.argv[1]))['lines_rejected']; sys.exit(any(k not in ('stale', 'too_large') for k in r))" "$REPORT" 2>/dev/null)" \
    "$(report lines_accepted) messages taken, rejected by kind: $REJECTED (only the stored values below may be)"
# The four stale NAV_* not taken, the posting over 1 MiB skipped (again at a registration while
# it is still the stored value), and the connection kept (the restart check counts them).
stored_values() {
    python3 -c "import json, sys; r = json.load(open(sys.argv[1]))['lines_rejected']; sys.exit(not (r.get('stale', 0) >= 4 and r.get('too_large', 0) >= 1))" "$REPORT" 2>/dev/null
}
FIRST_X="$(awk '$2 == "NAV_X" { print $4; exit }' "$WORK/onboard-out/run.alog" 2>/dev/null || true)"
check "stale, huge" "$(ok test "$(ok stored_values)" = 0 -a -n "$FIRST_X" -a "${FIRST_X%%.*}" != 999)" \
    "stale: $(report lines_rejected | grep -o "'stale': [0-9]*" || echo none), over 1 MiB: $(report lines_rejected | grep -o "'too_large': [0-9]*" || echo none); first NAV_X logged: ${FIRST_X:-none} (the stale one was 999)"

# set_points KEY LO HI: at least 50 postings, each in [LO, HI].
set_points() { [ "$(count "$1")" -ge 50 ] && in_range "$1" "$2" "$3"; }
check "DESIRED_HEADING" "$(ok set_points DESIRED_HEADING 0 359.999999)" \
    "$(count DESIRED_HEADING) postings, each in [0, 360) deg"
check "DESIRED_SPEED" "$(ok set_points DESIRED_SPEED 0 2.5)" \
    "$(count DESIRED_SPEED) postings, each in [0, 2.5] m/s"
check "DESIRED_DEPTH" "$(ok set_points DESIRED_DEPTH 0 100)" \
    "$(count DESIRED_DEPTH) postings, each in [0, 100] m"

# The manual override: CPT_PAUSED true with a stop, then false when it is lifted.
PAUSED="$(postings CPT_PAUSED | tr '\n' ' ' | sed 's/ $//')"
# The stop goes out with the pause, in the same packet just before it.
STOP_WHILE_PAUSED="$(awk -F'\t' '$4 != "pPlumetrace" { next }
    $3 == "CPT_PAUSED" && $5 == "true" && prev == "DESIRED_SPEED=0" { n++ }
    { prev = $3 "=" ($3 == "DESIRED_SPEED" ? $5 + 0 : $5) } END { print n + 0 }' "$TSV")"
paused_then_resumed() { echo "$PAUSED" | grep -q "true .*false" && [ "$STOP_WHILE_PAUSED" -ge 1 ]; }
check "CPT_PAUSED" "$(ok paused_then_resumed)" \
    "values in order: ${PAUSED:-none} (the connection cut at ${CUT_AT} s between them); pauses sent with DESIRED_SPEED = 0: $STOP_WHILE_PAUSED"
LAST_STATUS="$(postings CPT_STATUS | tail -n 1)"
check "CPT_STATUS" "$(ok test "$LAST_STATUS" = ended)" "last value: ${LAST_STATUS:-none}"

OP_AREA='pts={0.00,-100.00:300.00,-100.00:300.00,100.00:0.00,100.00},label=cpt_op_area,edge_color=yellow,vertex_color=yellow,vertex_size=2,edge_size=1'
P1="$(postings VIEW_POLYGON 1 | grep -cxF "$OP_AREA" || true)"
P2="$(postings VIEW_POLYGON 2 | grep -cxF "$OP_AREA" || true)"
check "VIEW_POLYGON" "$(ok test "$P1" -ge 1 -a "$P2" -ge 1)" \
    "the op-area (label=cpt_op_area) before the restart: $P1, after: $P2"
MARKER="$(postings VIEW_MARKER | grep -E '^type=diamond,x=-?[0-9.]+,y=-?[0-9.]+,label=cpt_estimate,color=orange,width=4$' | tail -n 1 || true)"
check "VIEW_MARKER" "$(ok test -n "$MARKER")" "$(count VIEW_MARKER) postings; last estimate: ${MARKER:-none}"
POINT="$(postings VIEW_POINT | grep -E '^x=-?[0-9.]+,y=-?[0-9.]+,label=cpt_lost_[0-9]+,vertex_color=red,vertex_size=4$' | head -n 1 || true)"
check "VIEW_POINT" "$(ok test -n "$POINT")" "$(count VIEW_POINT) postings; first: ${POINT:-none}"

# The consolidation period the MOOSDB asked for: taken from its timing replies, and no two
# packets of set-points sent closer than that (by the client's traffic log: the vehicle's
# receipt times bunch on a loaded machine) once the first reply has come. A stop is never held
# back, and the set-point waiting for the period goes with it, so a packet with a stop does not
# count.
PERIOD="$(grep -m1 -o 'consolidation period [0-9.]* s' "$LINKLOG" 2>/dev/null || true)"
GAPS="$(python3 - "$LINKLOG" <<'PY' 2>/dev/null || true
import sys
paced, sends, stops = False, [], set()
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) < 4:
        continue
    if f[1] == "#" and f[2] == "consolidation":
        paced = True
    if paced and f[1] == ">" and f[2] == "N":
        if f[3] == "DESIRED_HEADING":
            sends.append(f[0])
        elif f[3] == "DESIRED_SPEED" and f[5] == "0":
            stops.add(f[0])
times = [float(t) for t in sends if t not in stops]
gaps = [b - a for a, b in zip(times, times[1:])]
if gaps:
    print(f"{min(gaps):.3f} {sum(gaps) / len(gaps):.3f}")
PY
)"
paced() {
    [ -n "$PERIOD" ] && [ -n "$GAPS" ] &&
        awk -v g="${GAPS%% *}" -v p="$CONSOLIDATION_MS" 'BEGIN { exit !(g >= p / 1000 - 0.005) }'
}
check "consolidation" "$(ok paced)" \
    "MOOSDB --response=pPlumetrace:$CONSOLIDATION_MS; link.log: ${PERIOD:-none}; set-point gaps min/mean ${GAPS:-?} s"
SKEW="$(grep -m1 -o 'skew [^)]*' "$LINKLOG" 2>/dev/null || true)"
check "skew" "$(ok test "$SKEW" = "skew not estimated: the MOOSDB is on this host")" \
    "${SKEW:-none} (as libMOOS does for a MOOSDB on the same host)"

AFTER="$(count DESIRED_HEADING 2)"
CONNECTIONS="$(report connections)"
check "cut, restart" "$(ok test "$CONNECTIONS" = 3 -a "${WELCOMES:-0}" = 3 -a "$AFTER" -ge 20)" \
    "the client connected $CONNECTIONS times (the start, the cut, the restart); $AFTER DESIRED_HEADING postings after the MOOSDB came back"

echo "moos_interop: $PASSED passed, $FAILED failed (MOOSDB $(MOOSDB --moos_print_version 2>/dev/null | grep -m1 -io 'version[^,]*' || echo '?'))"
if [ "$FAILED" -gt 0 ]; then
    echo "moos_interop: logs: rerun with --keep to keep them; the onboard process's last lines:"
    tail -n 5 "$WORK/onboard.log" || true
    exit 1
fi
