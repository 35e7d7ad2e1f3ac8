//! Line framing: received bytes cut into lines at `\n`, whatever the chunks they came in; a line
//! longer than the limit is dropped whole (up to and including its `\n`) and reported once.

/// What the buffer gives next.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Piece {
    /// A whole line (its `\n` and any `\r` kept; bytes that are not UTF-8 replaced).
    Line(String),
    /// A line longer than the limit, with the bytes seen of it when it was dropped: the rest
    /// of it, up to its `\n`, is skipped, never read as a line of its own.
    TooLong(usize),
}

/// Bytes received and not yet a whole line.
#[derive(Debug)]
pub struct LineBuffer {
    buf: Vec<u8>,
    limit: usize,
    // Inside a line already reported too long: bytes are skipped up to its end.
    skipping: bool,
}

impl Default for LineBuffer {
    fn default() -> Self {
        LineBuffer::with_limit(usize::MAX)
    }
}

impl LineBuffer {
    /// A buffer whose lines may be at most `limit` bytes (the `\n` included).
    pub fn with_limit(limit: usize) -> Self {
        LineBuffer {
            buf: Vec::new(),
            limit: limit.max(1),
            skipping: false,
        }
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next whole line, or a line too long (reported once however it arrives), if one is
    /// there.
    pub fn next_piece(&mut self) -> Option<Piece> {
        loop {
            let end = self.buf.iter().position(|b| *b == b'\n');
            if self.skipping {
                match end {
                    Some(k) => {
                        self.buf.drain(..=k);
                        self.skipping = false;
                        continue;
                    }
                    None => {
                        self.buf.clear();
                        return None;
                    }
                }
            }
            return match end {
                Some(k) if k < self.limit => {
                    let raw: Vec<u8> = self.buf.drain(..=k).collect();
                    Some(Piece::Line(String::from_utf8_lossy(&raw).into_owned()))
                }
                Some(k) => {
                    self.buf.drain(..=k);
                    Some(Piece::TooLong(k + 1))
                }
                None if self.buf.len() > self.limit => {
                    let n = self.buf.len();
                    self.buf.clear();
                    self.skipping = true;
                    Some(Piece::TooLong(n))
                }
                None => None,
            };
        }
    }

    /// The next whole line (its `\n` and any `\r` kept; bytes that are not UTF-8 replaced), if
    /// one is there; lines too long are skipped.
    pub fn next_line(&mut self) -> Option<String> {
        loop {
            match self.next_piece()? {
                Piece::Line(l) => return Some(l),
                Piece::TooLong(_) => {}
            }
        }
    }

    /// Bytes waiting for their end of line.
    pub fn len(&self) -> usize {
        self.buf.len()
    }

    /// Whether no bytes are waiting.
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }

    /// Forgets what is buffered (a new connection starts with a new line).
    pub fn clear(&mut self) {
        self.buf.clear();
        self.skipping = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_come_whole_whatever_the_chunks() {
        let mut b = LineBuffer::default();
        let mut got = Vec::new();
        for chunk in [&b"$A*4"[..], b"1\r\n$B", b"*42\r\n\n$C"] {
            b.push(chunk);
            while let Some(line) = b.next_line() {
                got.push(line);
            }
        }
        assert_eq!(got, ["$A*41\r\n", "$B*42\r\n", "\n"]);
        assert_eq!(b.len(), 2);
        b.clear();
        assert!(b.is_empty() && b.next_line().is_none());
    }

    #[test]
    fn a_long_line_is_dropped_whole_and_reported_once() {
        let mut b = LineBuffer::with_limit(16);
        let mut got = Vec::new();
        let mut long = "X".repeat(40);
        long.push_str("$TAIL*00\r\n$OK*00\r\n");
        for chunk in long.as_bytes().chunks(7) {
            b.push(chunk);
            while let Some(p) = b.next_piece() {
                got.push(p);
            }
        }
        assert_eq!(got, [Piece::TooLong(21), Piece::Line("$OK*00\r\n".into())]);
        // A long line arriving whole in one chunk.
        b.push(format!("{}\n$OK*00\n", "Y".repeat(30)).as_bytes());
        assert_eq!(b.next_piece(), Some(Piece::TooLong(31)));
        assert_eq!(b.next_piece(), Some(Piece::Line("$OK*00\n".into())));
    }
}
