//! A line protocol on a line transport: the [`Link`] that carries a [`Protocol`] session over a
//! TCP stream or a serial device, with reconnection and back-off, counts of lines accepted and
//! rejected (by kind), the raw traffic written to a log, and chemical and current-meter lines
//! sharing the line routed to their own readers.

use super::conn::{Conn, Endpoint, read_tcp};
use super::lines::{LineBuffer, Piece};
use crate::link::{Backoff, Link, LinkEvent, LinkTiming, Outgoing};
use crate::protocol::chem::ChemFormat;
use crate::protocol::current::FlowFormat;
use crate::protocol::sentence::{LineCounts, MAX_LINE, SentenceError, UtcTime};
use crate::protocol::session::Protocol;
use std::io::Write;
use std::time::{Duration, Instant};

/// A protocol on a line transport, with reconnection, counts and a traffic log.
pub struct LineLink {
    endpoint: Endpoint,
    protocol: Box<dyn Protocol>,
    chem: Option<ChemFormat>,
    flow: Option<FlowFormat>,
    timing: LinkTiming,
    conn: Option<Conn>,
    lines: LineBuffer,
    last_byte: Instant,
    next_try: Instant,
    backoff: Backoff,
    counts: LineCounts,
    clock: UtcTime,
    traffic: Option<Box<dyn Write + Send>>,
    started: Instant,
    // A serial line silent for the silence timeout (reported once until bytes come again).
    quiet: bool,
    // Events from sending (a write that failed), reported by the next poll.
    deferred: Vec<LinkEvent>,
}

impl LineLink {
    /// A link to `endpoint` speaking `protocol`; chemical lines in `chem` travel on it too
    /// when given. Raw traffic goes to `traffic` (one line per line: seconds since start,
    /// `<` received, `>` sent, `!` rejected with the reason, `#` a link event).
    pub fn new(
        endpoint: Endpoint,
        protocol: Box<dyn Protocol>,
        chem: Option<ChemFormat>,
        timing: LinkTiming,
        traffic: Option<Box<dyn Write + Send>>,
    ) -> Self {
        let now = Instant::now();
        LineLink {
            endpoint,
            protocol,
            chem,
            flow: None,
            backoff: Backoff::new(&timing),
            timing,
            conn: None,
            lines: LineBuffer::with_limit(2 * MAX_LINE),
            last_byte: now,
            next_try: now,
            counts: LineCounts::default(),
            clock: UtcTime::default(),
            traffic,
            started: now,
            quiet: false,
            deferred: Vec::new(),
        }
    }

    /// The same link with current readings in `flow` travelling on it too.
    pub fn with_flow(mut self, flow: FlowFormat) -> Self {
        self.flow = Some(flow);
        self
    }

    /// Sets lock-step behaviour of the protocol (Iver polls after each command).
    pub fn set_lock_step(&mut self, on: bool) {
        self.protocol.set_lock_step(on);
    }

    fn log(&mut self, mark: char, text: &str) {
        if let Some(t) = self.traffic.as_mut() {
            let s = self.started.elapsed().as_secs_f64();
            let _ = writeln!(t, "{s:.3} {mark} {}", text.trim_end());
        }
    }

    fn drop_conn(&mut self, why: String, events: &mut Vec<LinkEvent>) {
        self.quiet = false;
        if self.conn.take().is_some() {
            self.log('#', &format!("lost: {why}"));
            events.push(LinkEvent::Lost(why));
        }
        self.lines.clear();
        self.next_try = Instant::now() + self.backoff.lost();
    }

    fn send_lines(&mut self, lines: Vec<String>, events: &mut Vec<LinkEvent>) {
        for line in lines {
            let Some(c) = self.conn.as_mut() else { return };
            match c.write_all(line.as_bytes()) {
                Ok(()) => self.log('>', &line),
                Err(e) => {
                    self.drop_conn(format!("writing: {e}"), events);
                    return;
                }
            }
        }
    }

    fn connect(&mut self, events: &mut Vec<LinkEvent>) {
        let now = Instant::now();
        if self.conn.is_some() || now < self.next_try {
            return;
        }
        match Conn::open(&self.endpoint) {
            Ok(c) => {
                self.conn = Some(c);
                self.backoff.connected();
                self.last_byte = now;
                self.log('#', "connected");
                events.push(LinkEvent::Connected);
                let hello = self.protocol.hello();
                self.send_lines(hello, events);
            }
            Err(e) => {
                self.log(
                    '#',
                    &format!(
                        "connecting failed: {e}; next try in {:.1} s",
                        self.backoff.current().as_secs_f64()
                    ),
                );
                self.next_try = now + self.backoff.failed();
            }
        }
    }

    fn take_line(&mut self, line: &str, events: &mut Vec<LinkEvent>) {
        self.log('<', line);
        if let Some(chem) = self.chem.as_ref().filter(|c| c.claims(line)) {
            let r = chem.parse(line);
            self.counts.count(&r);
            match r {
                Ok(v) => events.push(LinkEvent::Chem(v)),
                Err(e) => self.log('!', &e.to_string()),
            }
            return;
        }
        if let Some(flow) = self.flow.as_ref().filter(|f| f.claims(line)) {
            let r = flow.parse(line);
            self.counts.count(&r);
            match r {
                Ok(Some(v)) => events.push(LinkEvent::Flow(v)),
                Ok(None) => {}
                Err(e) => self.log('!', &e.to_string()),
            }
            return;
        }
        let before = events.len();
        let r = self.protocol.read(line, events);
        self.counts.count(&r);
        if let Err(e) = r {
            events.truncate(before);
            self.log('!', &e.to_string());
        }
        for e in &events[before..] {
            match e {
                LinkEvent::Clock(t) => self.clock = *t,
                LinkEvent::Nav(_) => self.backoff.carried(),
                _ => {}
            }
        }
    }
}

impl Link for LineLink {
    fn poll(&mut self, wait: Duration) -> Vec<LinkEvent> {
        let mut events = std::mem::take(&mut self.deferred);
        self.connect(&mut events);
        let deadline = Instant::now() + wait;
        let mut chunk = [0u8; 4096];
        loop {
            let now = Instant::now();
            let Some(conn) = self.conn.as_mut() else {
                // Down: wait out the interval (the caller's loop keeps its pace).
                std::thread::sleep(
                    deadline
                        .saturating_duration_since(now)
                        .min(Duration::from_millis(50)),
                );
                break;
            };
            let left = deadline.saturating_duration_since(now);
            match conn.read(&mut chunk, left) {
                Ok(0) => {}
                Ok(n) => {
                    self.last_byte = Instant::now();
                    if self.quiet {
                        self.quiet = false;
                        self.log('#', "the line speaks again");
                    }
                    self.lines.push(&chunk[..n]);
                    while let Some(piece) = self.lines.next_piece() {
                        match piece {
                            Piece::Line(line) if line.trim().is_empty() => {}
                            Piece::Line(line) => self.take_line(&line, &mut events),
                            Piece::TooLong(n) => {
                                let r: Result<(), _> = Err(SentenceError::TooLong(n));
                                self.counts.count(&r);
                                self.log('!', &format!("a line of over {n} bytes was dropped"));
                            }
                        }
                    }
                }
                Err(e) => {
                    self.drop_conn(e.to_string(), &mut events);
                    break;
                }
            }
            if self.conn.is_some() && self.last_byte.elapsed() >= self.timing.silence_timeout {
                let s = self.timing.silence_timeout.as_secs_f64();
                let why = format!("nothing received for {s:.1} s");
                if matches!(self.conn, Some(Conn::Serial(_))) {
                    // A serial device stays: reopening it would not bring the vehicle back.
                    if !self.quiet {
                        self.quiet = true;
                        self.log('#', &format!("silent: {why}"));
                        events.push(LinkEvent::Quiet(why));
                    }
                } else {
                    self.drop_conn(why, &mut events);
                    break;
                }
            }
            if !events.is_empty() || Instant::now() >= deadline {
                break;
            }
        }
        if self.conn.is_some() {
            let clock = self.clock;
            let lines = self.protocol.tick(Instant::now(), clock, &mut events);
            self.send_lines(lines, &mut events);
        }
        events
    }

    fn send(&mut self, what: Outgoing, time: UtcTime) {
        let mut events = Vec::new();
        let lines = self.protocol.write(what, time, Instant::now());
        self.send_lines(lines, &mut events);
        self.deferred.extend(events);
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
    }

    fn counts(&self) -> &LineCounts {
        &self.counts
    }

    fn connected(&self) -> bool {
        self.conn.is_some()
    }

    fn close(&mut self) {
        if let Some(t) = self.traffic.as_mut() {
            let _ = t.flush();
        }
        // Closing a TCP socket with unread data resets the connection, and the other side may
        // then drop what it had not read yet (the final stop): end the sending side, then read
        // what is left until the other side closes or half a second has passed.
        if let Some(Conn::Tcp(s)) = self.conn.as_mut() {
            let _ = s.flush();
            let _ = s.shutdown(std::net::Shutdown::Write);
            let deadline = Instant::now() + Duration::from_millis(500);
            let mut chunk = [0u8; 4096];
            while Instant::now() < deadline {
                let left = deadline.saturating_duration_since(Instant::now());
                match read_tcp(s, &mut chunk, left.min(Duration::from_millis(50))) {
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
        }
        self.conn = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::sentence::frame;
    use crate::protocol::session::{Bluefin, BluefinSettings};
    use std::net::TcpListener;

    /// Everything a link reports until the other side closes.
    fn events_of(
        server: impl FnOnce(std::net::TcpStream) + Send + 'static,
    ) -> (Vec<LinkEvent>, LineCounts) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap_or_else(|e| panic!("{e}"));
        let addr = listener.local_addr().unwrap_or_else(|e| panic!("{e}"));
        let t = std::thread::spawn(move || {
            if let Ok((s, _)) = listener.accept() {
                server(s);
            }
        });
        let secs = Duration::from_secs_f64;
        let protocol = Bluefin::new(BluefinSettings {
            ack_timeout: secs(5.0),
            ack_tries: 3,
            status_period: secs(1.0),
            safe_stop: true,
        });
        let timing = LinkTiming {
            silence_timeout: secs(10.0),
            reconnect_min: secs(60.0),
            reconnect_max: secs(60.0),
        };
        let mut link = LineLink::new(
            Endpoint::Tcp(addr.to_string()),
            Box::new(protocol),
            None,
            timing,
            None,
        );
        let mut events = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(20);
        while Instant::now() < deadline {
            let got = link.poll(Duration::from_millis(50));
            let lost = got.iter().any(|e| matches!(e, LinkEvent::Lost(_)));
            events.extend(got);
            if lost {
                break;
            }
        }
        let _ = t.join();
        (events, link.counts().clone())
    }

    #[test]
    fn an_over_long_line_is_dropped_whole_and_counted_once() {
        let (events, counts) = events_of(|mut s| {
            let pause = || std::thread::sleep(Duration::from_millis(100));
            // 2 kB with no end of line, whose tail is a valid sentence: not a line of its own.
            let _ = s.write_all(&[b'X'; 1100]);
            pause();
            let _ = s.write_all(frame("BFCTL,120000.000,0").as_bytes());
            pause();
            // 100 kB in one line, in pieces.
            for _ in 0..25 {
                let _ = s.write_all(&[b'Y'; 4000]);
                pause();
            }
            let _ = s.write_all(b"\r\n");
            let _ = s.write_all(frame("BFCTL,120001.000,1").as_bytes());
            pause();
        });
        let accepting: Vec<bool> = events
            .iter()
            .filter_map(|e| match e {
                LinkEvent::Accepting(a) => Some(*a),
                _ => None,
            })
            .collect();
        assert_eq!(accepting, [true], "{events:?}");
        assert_eq!(counts.rejected.get("too_long"), Some(&2), "{counts:?}");
        assert_eq!(counts.accepted, 1, "{counts:?}");
    }
}
