//! Connections a vehicle link's lines travel on: a TCP stream or a serial device, opened from an
//! [`Endpoint`], read with a wait and written whole.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::time::Duration;

/// Where a link's lines travel.
#[derive(Debug, Clone, PartialEq)]
pub enum Endpoint {
    /// A TCP server (`host:port`).
    Tcp(String),
    /// A serial device (or pseudo-terminal) path, set to raw mode at `baud`.
    Serial {
        /// Device path.
        path: PathBuf,
        /// Baud rate.
        baud: u32,
    },
}

/// Reads what a TCP stream has within `wait` (`Ok(0)`: nothing came; no wait at all is a
/// non-blocking read, since read timeouts round up to the kernel's tick); the peer closing the
/// connection is an `UnexpectedEof` error.
pub fn read_tcp(s: &mut TcpStream, buf: &mut [u8], wait: Duration) -> std::io::Result<usize> {
    s.set_nonblocking(wait.is_zero())?;
    s.set_read_timeout(Some(wait.max(Duration::from_millis(1))))?;
    match s.read(buf) {
        Ok(0) => Err(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            "the other side closed the connection",
        )),
        Ok(n) => Ok(n),
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) =>
        {
            Ok(0)
        }
        Err(e) => Err(e),
    }
}

/// An open connection: a TCP stream or a serial device.
pub(crate) enum Conn {
    Tcp(TcpStream),
    Serial(std::fs::File),
}

impl Conn {
    /// Opens `e` (TCP: within 2 s, no delay; serial: raw mode at its baud rate).
    pub(crate) fn open(e: &Endpoint) -> std::io::Result<Conn> {
        match e {
            Endpoint::Tcp(addr) => {
                let addr = std::net::ToSocketAddrs::to_socket_addrs(addr.as_str())?
                    .next()
                    .ok_or_else(|| std::io::Error::other(format!("{addr}: no address")))?;
                let s = TcpStream::connect_timeout(&addr, Duration::from_secs(2))?;
                s.set_nodelay(true)?;
                Ok(Conn::Tcp(s))
            }
            Endpoint::Serial { path, baud } => {
                let f = std::fs::OpenOptions::new()
                    .read(true)
                    .write(true)
                    .open(path)?;
                super::serial::set_raw(&f, *baud)?;
                Ok(Conn::Serial(f))
            }
        }
    }

    /// Reads what is there within `wait`: `Ok(0)` when nothing came.
    pub(crate) fn read(&mut self, buf: &mut [u8], wait: Duration) -> std::io::Result<usize> {
        match self {
            Conn::Tcp(s) => read_tcp(s, buf, wait),
            // Raw mode with VMIN 0 and VTIME 1: a read returns after 0.1 s without data.
            Conn::Serial(f) => match f.read(buf) {
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Ok(0),
                other => other,
            },
        }
    }

    /// Writes all of `b`.
    pub(crate) fn write_all(&mut self, b: &[u8]) -> std::io::Result<()> {
        match self {
            Conn::Tcp(s) => s.write_all(b),
            Conn::Serial(f) => f.write_all(b),
        }
    }
}
