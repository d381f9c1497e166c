//! OMG CDR (XCDR1, the encoding ROS 2 writes): a 4-byte encapsulation header (`00 00` big
//! endian, `00 01` little endian, then two option bytes), then the fields, each aligned to its
//! own size (up to 8) counted from the end of the header. Strings are a `u32` length that counts
//! the terminating NUL, the bytes, and the NUL; sequences a `u32` element count and the
//! elements. [`CdrReader`] reads without copying; [`CdrWriter`] writes the same layout (tests,
//! round trips).

use crate::BagError;

/// Reads CDR fields from a message, borrowing strings and byte sequences.
#[derive(Debug)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
    little: bool,
}

const ORIGIN: usize = 4;

impl<'a> CdrReader<'a> {
    /// Starts after the encapsulation header.
    ///
    /// # Errors
    /// [`BagError::Cdr`] for a message shorter than the header or an unknown encapsulation.
    pub fn new(buf: &'a [u8]) -> Result<Self, BagError> {
        let Some(header) = buf.get(..ORIGIN) else {
            return Err(BagError::cdr(
                0,
                "message shorter than the 4-byte CDR header",
            ));
        };
        let little = match (header[0], header[1]) {
            (0, 1) | (0, 3) => true,  // CDR_LE, PL_CDR_LE
            (0, 0) | (0, 2) => false, // CDR_BE, PL_CDR_BE
            _ => {
                return Err(BagError::cdr(
                    0,
                    format!(
                        "unknown CDR encapsulation {:02x} {:02x}",
                        header[0], header[1]
                    ),
                ));
            }
        };
        Ok(Self {
            buf,
            pos: ORIGIN,
            little,
        })
    }

    /// Byte offset of the next field in the message.
    pub fn position(&self) -> usize {
        self.pos
    }

    fn align(&mut self, n: usize) {
        let rel = self.pos - ORIGIN;
        self.pos += (n - rel % n) % n;
    }

    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], BagError> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|e| *e <= self.buf.len())
            .ok_or_else(|| {
                BagError::cdr(
                    self.pos,
                    format!(
                        "{what}: {n} bytes needed, {} left",
                        self.buf.len().saturating_sub(self.pos)
                    ),
                )
            })?;
        let s = &self.buf[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &'static str) -> Result<[u8; N], BagError> {
        self.align(N);
        let s = self.take(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if !self.little {
            a.reverse();
        }
        Ok(a)
    }

    /// An octet.
    pub fn u8(&mut self, what: &'static str) -> Result<u8, BagError> {
        Ok(self.take(1, what)?[0])
    }

    /// An unsigned 32-bit integer.
    pub fn u32(&mut self, what: &'static str) -> Result<u32, BagError> {
        Ok(u32::from_le_bytes(self.array::<4>(what)?))
    }

    /// A signed 32-bit integer.
    pub fn i32(&mut self, what: &'static str) -> Result<i32, BagError> {
        Ok(i32::from_le_bytes(self.array::<4>(what)?))
    }

    /// A 64-bit float.
    pub fn f64(&mut self, what: &'static str) -> Result<f64, BagError> {
        Ok(f64::from_le_bytes(self.array::<8>(what)?))
    }

    /// A string (UTF-8, NUL-terminated, its length counting the NUL).
    pub fn string(&mut self, what: &'static str) -> Result<&'a str, BagError> {
        let at = self.pos;
        let n = self.u32(what)? as usize;
        if n == 0 {
            return Ok(""); // some writers encode the empty string with length 0
        }
        let bytes = self.take(n, what)?;
        let (body, nul) = bytes.split_at(n - 1);
        if nul != [0] {
            return Err(BagError::cdr(at, format!("{what}: string without its NUL")));
        }
        std::str::from_utf8(body).map_err(|_| BagError::cdr(at, format!("{what}: not UTF-8")))
    }

    /// A sequence of octets.
    pub fn bytes(&mut self, what: &'static str) -> Result<&'a [u8], BagError> {
        let n = self.u32(what)? as usize;
        self.take(n, what)
    }
}

/// Writes CDR fields (little endian, `CDR_LE`), as ROS 2 does.
#[derive(Debug, Default)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl CdrWriter {
    /// A message with the `CDR_LE` header.
    pub fn new() -> Self {
        Self {
            buf: vec![0, 1, 0, 0],
        }
    }

    fn align(&mut self, n: usize) {
        while !(self.buf.len() - ORIGIN).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    /// An octet.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.buf.push(v);
        self
    }

    /// An unsigned 32-bit integer.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// A signed 32-bit integer.
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// A 64-bit float.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// A string.
    pub fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }

    /// A sequence of octets.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.buf.extend_from_slice(b);
        self
    }

    /// The message.
    pub fn finish(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.buf)
    }
}
