//! The front seat's end of the line: accepting a back seat on the TCP port, sending lines (with
//! the drop fault), reading what comes back into lines, and the restart fault.

use crate::seat::FrontSeat;
use plumetrace_onboard::transport::conn::read_tcp;
use plumetrace_onboard::transport::serial::Pty;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::time::{Duration, Instant};

/// The front seat's end of the line: a listening TCP port and the back seat's connection, or
/// the controlling end of a pseudo-terminal.
pub(crate) enum Wire {
    Tcp {
        addr: SocketAddr,
        listener: Option<TcpListener>,
        conn: Option<TcpStream>,
    },
    Pty(Pty),
}

impl FrontSeat {
    /// Whether a back seat is connected (a pseudo-terminal always is).
    pub(crate) fn connected(&self) -> bool {
        match &self.wire {
            Wire::Tcp { conn, .. } => conn.is_some(),
            Wire::Pty(_) => true,
        }
    }

    /// Accepts a back seat, waiting up to `wait`.
    pub(crate) fn accept(&mut self, wait: Duration) {
        let Wire::Tcp { listener, conn, .. } = &mut self.wire else {
            return;
        };
        let Some(l) = listener.as_ref() else { return };
        if conn.is_some() {
            return;
        }
        let deadline = Instant::now() + wait;
        let _ = l.set_nonblocking(true);
        loop {
            match l.accept() {
                Ok((s, _)) => {
                    let _ = s.set_nonblocking(false);
                    let _ = s.set_nodelay(true);
                    *conn = Some(s);
                    self.lines.clear();
                    self.stat(|s| s.connections += 1);
                    return;
                }
                Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
                Err(_) => return,
            }
        }
    }

    /// Sends a line, unless the drop fault draws it; a failed write loses the connection.
    pub(crate) fn send(&mut self, line: &str) {
        if self.drop > 0.0 && self.rng.unit() < self.drop {
            self.dropped += 1;
            return;
        }
        let failed = match &mut self.wire {
            Wire::Tcp { conn: Some(c), .. } => c.write_all(line.as_bytes()).is_err(),
            Wire::Tcp { conn: None, .. } => false,
            Wire::Pty(p) => p.controller.write_all(line.as_bytes()).is_err(),
        };
        if failed && let Wire::Tcp { conn, .. } = &mut self.wire {
            *conn = None;
        }
    }

    /// Reads what arrives within `wait` and returns the complete lines.
    pub(crate) fn read_lines(&mut self, wait: Duration) -> Vec<String> {
        let mut chunk = [0u8; 4096];
        let n = match &mut self.wire {
            Wire::Tcp { conn: Some(c), .. } => read_tcp(c, &mut chunk, wait).map_err(|_| ()),
            Wire::Tcp { conn: None, .. } => {
                std::thread::sleep(wait.min(Duration::from_millis(10)));
                Ok(0)
            }
            Wire::Pty(p) => {
                let deadline = Instant::now() + wait;
                loop {
                    match p.controller.read(&mut chunk) {
                        Ok(n) if n > 0 => {
                            self.pty_heard = true;
                            break Ok(n);
                        }
                        Err(e) if e.kind() != std::io::ErrorKind::WouldBlock => {
                            // No back seat has the device open: not yet, or no more.
                            if self.pty_heard && self.lock_step {
                                if let Ok(mut st) = self.stats.lock() {
                                    st.back_seat_gone = true;
                                }
                                break Ok(0);
                            }
                            std::thread::sleep(wait.min(Duration::from_millis(20)));
                            break Ok(0);
                        }
                        _ if Instant::now() >= deadline => break Ok(0),
                        _ => std::thread::sleep(Duration::from_micros(200)),
                    }
                }
            }
        };
        match n {
            Ok(n) => self.lines.push(&chunk[..n]),
            Err(()) => {
                if let Wire::Tcp { conn, .. } = &mut self.wire {
                    *conn = None;
                }
                self.lines.clear();
            }
        }
        let mut lines = Vec::new();
        while let Some(line) = self.lines.next_line() {
            lines.push(line);
        }
        if self.lines.len() > 4096 {
            self.lines.clear();
        }
        lines
    }

    /// Restarts the front seat if the restart fault is due at mission time `t`.
    pub(crate) fn maybe_restart(&mut self, t: f64) {
        let Some((at, pause)) = self.restart else {
            return;
        };
        if t < at {
            return;
        }
        self.restart = None;
        match &mut self.wire {
            Wire::Tcp {
                addr,
                listener,
                conn,
            } => {
                *conn = None;
                *listener = None;
                std::thread::sleep(pause);
                *listener = TcpListener::bind(*addr).ok();
            }
            Wire::Pty(p) => {
                // An Iver's computer restarting: the serial line stays, but nothing answers
                // and what the back seat sends meanwhile is lost; it comes back with a line of
                // boot text (not a sentence) and answers polls again.
                let deadline = Instant::now() + pause;
                let mut chunk = [0u8; 4096];
                while Instant::now() < deadline {
                    if !matches!(p.controller.read(&mut chunk), Ok(n) if n > 0) {
                        std::thread::sleep(Duration::from_millis(10));
                    }
                }
                let _ = p.controller.write_all(b"remote helm restarted\r\n");
                self.polled = false;
            }
        }
        self.stat(|s| s.restarts += 1);
        self.lines.clear();
    }
}
