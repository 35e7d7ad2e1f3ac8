//! Line framing: received bytes cut into lines at `\n`, whatever the chunks they came in.

/// Bytes received and not yet a whole line.
#[derive(Debug, Default)]
pub struct LineBuffer {
    buf: Vec<u8>,
}

impl LineBuffer {
    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next whole line (its `\n` and any `\r` kept; bytes that are not UTF-8 replaced), if
    /// one is there.
    pub fn next_line(&mut self) -> Option<String> {
        let k = self.buf.iter().position(|b| *b == b'\n')?;
        let raw: Vec<u8> = self.buf.drain(..=k).collect();
        Some(String::from_utf8_lossy(&raw).into_owned())
    }

    /// Bytes waiting for their end of line.
    pub fn len(&self) -> usize {
        self.buf.len()
    }

    /// Whether no bytes are waiting.
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }

    /// Forgets what is buffered.
    pub fn clear(&mut self) {
        self.buf.clear();
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
}
