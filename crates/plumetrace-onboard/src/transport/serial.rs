//! Serial lines without a system library: raw mode and the baud rate through `rustix`'s
//! termios, and pseudo-terminals for rehearsals (a simulated front seat on one machine).

use rustix::termios::{self, OptionalActions, SpecialCodeIndex};
use std::fs::File;
use std::os::fd::AsFd;

/// Puts a serial device (or a pseudo-terminal's end) in raw mode at `baud`, with reads that
/// return after 0.1 s without data.
pub fn set_raw(f: &impl AsFd, baud: u32) -> std::io::Result<()> {
    let mut t = termios::tcgetattr(f)?;
    t.make_raw();
    t.special_codes[SpecialCodeIndex::VMIN] = 0;
    t.special_codes[SpecialCodeIndex::VTIME] = 1;
    t.set_speed(baud)?;
    termios::tcsetattr(f, OptionalActions::Now, &t)?;
    Ok(())
}

/// A pseudo-terminal: the controlling end (kept by whoever plays the vehicle) and the path of
/// the other end (a device a back seat opens like a serial port).
pub struct Pty {
    /// The controlling end, raw and non-blocking (a read without data fails with
    /// `WouldBlock`; the 0.1 s read timeout of raw mode applies to the device end only).
    pub controller: File,
    /// The path of the device end (`/dev/pts/N`).
    pub path: std::path::PathBuf,
}

impl Pty {
    /// Opens a new pseudo-terminal pair.
    pub fn open() -> std::io::Result<Pty> {
        use rustix::pty::{OpenptFlags, grantpt, openpt, ptsname, unlockpt};
        let fd = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY)?;
        grantpt(&fd)?;
        unlockpt(&fd)?;
        let name = ptsname(&fd, Vec::new())?;
        let path = std::path::PathBuf::from(name.to_string_lossy().into_owned());
        rustix::fs::fcntl_setfl(&fd, rustix::fs::OFlags::RDWR | rustix::fs::OFlags::NONBLOCK)?;
        let controller = File::from(fd);
        set_raw(&controller, 19_200)?;
        Ok(Pty { controller, path })
    }
}
