#!/usr/bin/env python3
"""A small simulated vehicle for scripts/moos_interop.sh: a MOOS community client (Python's
standard library only) that flies a point vehicle from DESIRED_HEADING and DESIRED_SPEED,
posts NAV_X, NAV_Y, NAV_HEADING, NAV_SPEED, NAV_DEPTH, NAV_ALTITUDE and a chemical reading at
10 Hz, and writes every posting it is notified of to a log (tab-separated: seconds since it
started, its connection number, the variable, the source, the value).

The wire format is the one crates/plumetrace-onboard/src/moos/wire.rs documents: little-endian
packets of messages, the `ELKS CAN'T DANCE 2/8/10` handshake, a timing message each second.
It reconnects when the MOOSDB goes away, and posts MOOS_MANUAL_OVERRIDE when told to.

With --prime stale it only posts NAV_X, NAV_Y, NAV_HEADING and NAV_SPEED of a vehicle far from
the one that will fly, stamped 50 s ago (the values a MOOSDB keeps and sends to a client that
registers later, as a vehicle that stopped posting would leave them); with --prime huge, a
MOOS_MANUAL_OVERRIDE string of 1.5 MiB; then it disconnects.

With --proxy PORT it is no vehicle but a TCP relay: it listens on PORT, passes each connection
through to the MOOSDB, and cuts the open ones when sent SIGUSR1, as a lost network would,
while the MOOSDB stays up.

The plume: the water flows toward the east; a source at (--source-x, --source-y) spreads a
Gaussian plume downflow of it whose width grows one metre per ten, with a peak reading of 1.
"""

import argparse
import math
import select
import signal
import socket
import struct
import sys
import time

PROTOCOL = b"ELKS CAN'T DANCE 2/8/10".ljust(32, b"\0")
# The water depth under the vehicle, m (NAV_ALTITUDE is what is left of it below NAV_DEPTH).
WATER_DEPTH_M = 20.0
WATCHED = [
    "DESIRED_HEADING",
    "DESIRED_SPEED",
    "DESIRED_DEPTH",
    "CPT_STATUS",
    "CPT_PAUSED",
    "CPT_BEHAVIOUR",
    "CPT_DETECTION",
    "CPT_DECLARATION",
    "VIEW_POLYGON",
    "VIEW_SEGLIST",
    "VIEW_MARKER",
    "VIEW_POINT",
]


def moos_string(b):
    return struct.pack("<i", len(b)) + b


def message(kind, key, t, double=-1.0, string=None, source="", msg_id=-1):
    """One message's bytes (CMOOSMsg::Serialize): double data unless `string` is given."""
    data_type = b"D" if string is None else b"S"
    body = (
        struct.pack("<i", msg_id)
        + kind
        + data_type
        + moos_string(source.encode())
        + moos_string(b"")
        + moos_string(b"")
        + moos_string(key.encode())
        + struct.pack("<ddd", t, double, -1.0)
        + moos_string((string or "").encode())
    )
    return struct.pack("<i", 4 + len(body)) + body


def packet(messages):
    body = b"".join(messages)
    return struct.pack("<ii", 9 + len(body), len(messages)) + b"\0" + body


def decode_packet(p):
    """The messages of one packet as (type, data type, source, key, time, double, string)."""
    count = struct.unpack_from("<i", p, 4)[0]
    at = 9
    out = []
    for _ in range(count):
        length = struct.unpack_from("<i", p, at)[0]
        m = p[at : at + length]
        at += length
        kind, data_type = m[8:9], m[9:10]
        pos = 10
        fields = []
        for _ in range(4):
            n = struct.unpack_from("<i", m, pos)[0]
            fields.append(m[pos + 4 : pos + 4 + n].decode("utf-8", "replace"))
            pos += 4 + n
        t, double, _ = struct.unpack_from("<ddd", m, pos)
        pos += 24
        n = struct.unpack_from("<i", m, pos)[0]
        string = m[pos + 4 : pos + 4 + n].decode("utf-8", "replace")
        out.append((kind, data_type, fields[0], fields[3], t, double, string))
    return out


class Vehicle:
    def __init__(self, args, log):
        self.args = args
        self.x, self.y = args.start_x, args.start_y
        self.heading, self.speed = 90.0, 1.0
        self.want_heading, self.want_speed = self.heading, self.speed
        self.depth = 2.0
        self.sock = None
        self.buf = b""
        self.conn = 0
        self.next_id = 0
        self.last_timing = 0.0
        self.started = time.time()
        self.log = log

    def now(self):
        return time.time() - self.started

    def note(self, text):
        print(f"vehicle: {self.now():6.2f} s: {text}", file=sys.stderr, flush=True)

    def reading(self):
        dx = self.x - self.args.source_x
        dy = self.y - self.args.source_y
        if dx <= 0.0:
            return 0.0
        sigma = 1.0 + 0.1 * dx
        return math.exp(-0.5 * (dy / sigma) ** 2)

    def connect(self):
        try:
            s = socket.create_connection(("127.0.0.1", self.args.port), timeout=2.0)
            s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            hello = message(b"i", "asynchronous", time.time(), string=self.args.name)
            s.sendall(PROTOCOL + packet([hello]))
            self.sock, self.buf = s, b""
            welcome = self.read_packets(2.0, want_welcome=True)
        except OSError as e:
            self.drop(f"connecting: {e}")
            return
        if not welcome:
            self.drop("no welcome")
            return
        self.conn += 1
        self.note(f"connected (connection {self.conn})")
        regs = [self.msg(b"R", v, 0.0) for v in WATCHED]
        self.send(regs)

    def drop(self, why):
        if self.sock is not None:
            self.note(f"lost the MOOSDB: {why}")
            self.sock.close()
        self.sock = None

    def msg(self, kind, key, double=-1.0, string=None):
        m = message(
            kind, key, time.time(), double, string, self.args.name, self.next_id
        )
        self.next_id += 1
        return m

    def send(self, messages):
        if self.sock is None:
            return
        if time.time() - self.last_timing >= 1.0:
            self.last_timing = time.time()
            messages = [message(b"T", "_async_timing", time.time(), 0.0)] + messages
        try:
            self.sock.sendall(packet(messages))
        except OSError as e:
            self.drop(f"writing: {e}")

    def read_packets(self, wait, want_welcome=False):
        """Reads what arrives within `wait` seconds; with `want_welcome`, until the welcome."""
        until = time.time() + wait
        while self.sock is not None:
            left = until - time.time()
            if left <= 0:
                return False
            ready, _, _ = select.select([self.sock], [], [], left)
            if not ready:
                return False
            chunk = self.sock.recv(65536)
            if not chunk:
                self.drop("the MOOSDB closed the connection")
                return False
            self.buf += chunk
            while len(self.buf) >= 4:
                n = struct.unpack_from("<i", self.buf)[0]
                if len(self.buf) < n:
                    break
                p, self.buf = self.buf[:n], self.buf[n:]
                for m in decode_packet(p):
                    if m[0] == b"W":
                        return True
                    if m[0] == b"K":
                        self.drop(f"refused: {m[6]}")
                        return False
                    if m[0] == b"N":
                        self.take(m)
            if not want_welcome:
                return False
        return False

    def take(self, m):
        _, data_type, source, key, _, double, string = m
        value = repr(double) if data_type == b"D" else string
        value = value.replace("\t", " ").replace("\n", " ")
        self.log.write(f"{self.now():.3f}\t{self.conn}\t{key}\t{source}\t{value}\n")
        if data_type == b"D" and math.isfinite(double):
            if key == "DESIRED_HEADING":
                self.want_heading = double % 360.0
            elif key == "DESIRED_SPEED":
                self.want_speed = max(0.0, min(double, 3.0))
            elif key == "DESIRED_DEPTH":
                self.depth = max(0.0, min(double, 100.0))

    def step(self, dt):
        # Turns at up to 30 deg/s the short way round; speed and depth follow at once.
        turn = (self.want_heading - self.heading + 540.0) % 360.0 - 180.0
        turn = max(-30.0 * dt, min(30.0 * dt, turn))
        self.heading = (self.heading + turn) % 360.0
        self.speed = self.want_speed
        h = math.radians(self.heading)
        self.x += self.speed * math.sin(h) * dt
        self.y += self.speed * math.cos(h) * dt

    def prime(self, what):
        self.connect()
        if self.sock is None:
            sys.exit("vehicle: --prime: no MOOSDB")
        if what == "stale":
            old = time.time() - 50.0
            posts = [
                message(b"N", k, old, v, source=self.args.name)
                for k, v in [
                    ("NAV_X", 999.0),
                    ("NAV_Y", 999.0),
                    ("NAV_HEADING", 0.0),
                    ("NAV_SPEED", 1.0),
                ]
            ]
            told = "NAV_* at (999, 999) stamped 50 s ago"
        else:
            # A string: a MOOSDB keeps a variable's type, and the override is a string.
            posts = [self.msg(b"N", "MOOS_MANUAL_OVERRIDE", string="x" * (1536 * 1024))]
            told = "MOOS_MANUAL_OVERRIDE of 1.5 MiB"
        self.send(posts)
        # The MOOSDB has them once it answers the next timing message.
        self.last_timing = 0.0
        self.send([])
        self.read_packets(1.0)
        self.note(f"primed: {told}")
        self.drop("primed")

    def run(self):
        a = self.args
        override = []
        if a.override_at is not None:
            override = [
                (a.override_at, "true"),
                (a.override_at + a.override_for, "false"),
            ]
        last = self.now()
        next_try = 0.0
        while self.now() < a.duration:
            if self.sock is None and self.now() >= next_try:
                self.connect()
                next_try = self.now() + 0.2
            t = self.now()
            self.step(t - last)
            last = t
            posts = [
                self.msg(b"N", "NAV_X", self.x),
                self.msg(b"N", "NAV_Y", self.y),
                self.msg(b"N", "NAV_HEADING", self.heading),
                self.msg(b"N", "NAV_SPEED", self.speed),
                self.msg(b"N", "NAV_DEPTH", self.depth),
                self.msg(b"N", "NAV_ALTITUDE", WATER_DEPTH_M - self.depth),
                self.msg(b"N", a.chem_variable, self.reading()),
            ]
            while override and t >= override[0][0] and self.sock is not None:
                posts.append(
                    self.msg(b"N", "MOOS_MANUAL_OVERRIDE", string=override[0][1])
                )
                self.note(f"MOOS_MANUAL_OVERRIDE = {override[0][1]}")
                override.pop(0)
            self.send(posts)
            end = time.time() + 0.1
            while self.sock is not None and time.time() < end:
                try:
                    self.read_packets(end - time.time())
                except (OSError, struct.error) as e:
                    self.drop(f"reading: {e}")
            if self.sock is None:
                time.sleep(max(0.0, end - time.time()))
        self.drop("done")


def proxy(args):
    """Relays connections on --proxy to the MOOSDB; cuts the open ones on SIGUSR1."""
    listener = socket.socket()
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    listener.bind(("127.0.0.1", args.proxy))
    listener.listen(4)
    started = time.time()
    pairs = []
    cut = []
    signal.signal(signal.SIGUSR1, lambda *_: cut.append(True))
    while time.time() - started < args.duration:
        socks = [listener] + [s for p in pairs for s in p]
        try:
            ready, _, _ = select.select(socks, [], [], 0.05)
        except InterruptedError:
            ready = []
        for s in ready:
            if s is listener:
                client, _ = listener.accept()
                try:
                    pairs.append((client, socket.create_connection(("127.0.0.1", args.port), 2.0)))
                except OSError:
                    client.close()
                continue
            pair = next(p for p in pairs if s in p)
            other = pair[1] if s is pair[0] else pair[0]
            try:
                data = s.recv(65536)
                if data:
                    other.sendall(data)
                    continue
            except OSError:
                pass
            for x in pair:
                x.close()
            pairs.remove(pair)
        if cut:
            cut.clear()
            print(f"proxy: {time.time() - started:6.2f} s: cutting {len(pairs)} connection(s)", file=sys.stderr, flush=True)
            for pair in pairs:
                for x in pair:
                    x.close()
            pairs = []


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--port", type=int, required=True)
    p.add_argument("--log", required=True, help="where the postings received go")
    p.add_argument("--name", default="uSimVehicle")
    p.add_argument("--duration", type=float, default=60.0, help="seconds to fly")
    p.add_argument("--chem-variable", default="CHEM_READING")
    p.add_argument("--start-x", type=float, default=120.0)
    p.add_argument("--start-y", type=float, default=0.0)
    p.add_argument("--source-x", type=float, default=100.0)
    p.add_argument("--source-y", type=float, default=0.0)
    p.add_argument(
        "--override-at", type=float, help="post MOOS_MANUAL_OVERRIDE = true then"
    )
    p.add_argument("--override-for", type=float, default=3.0)
    p.add_argument(
        "--prime",
        choices=["stale", "huge"],
        help="only post stale NAV_* or an override string over 1 MiB, then leave",
    )
    p.add_argument("--proxy", type=int, help="relay this port to the MOOSDB instead")
    args = p.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    if args.proxy is not None:
        proxy(args)
        return
    with open(args.log, "w", buffering=1) as log:
        if args.prime:
            Vehicle(args, log).prime(args.prime)
        else:
            Vehicle(args, log).run()


if __name__ == "__main__":
    main()
