//! Bit packing for `.ibk` version 3: a little-endian bit writer and a bounds-checked reader, and
//! Rice codes (Golomb codes with a power-of-two divisor) for the zig-zagged prediction residuals.
//! A Rice code of parameter `k` writes `u >> k` in unary and the `k` low bits of `u`: near-optimal
//! for the two-sided geometric (Laplacian-like) residuals of smooth motion, and it needs no tables,
//! so a decoder can start at any segment.

use crate::{MocapError, Result};

/// Unary quotients this long or longer are escaped: `ESCAPE` ones, then the value's bit length in
/// 6 bits and its bits. Bounds both a decoder's loop and a hostile file's cost.
const ESCAPE: u64 = 24;

/// Largest zig-zagged residual the format stores (a value needs at most 42 bits).
pub const MAX_RICE_VALUE: u64 = (1 << 42) - 1;

/// Appends bits, least significant first.
#[derive(Default)]
pub struct BitWriter {
    bytes: Vec<u8>,
    acc: u64,
    n: u32,
}

impl BitWriter {
    pub fn new() -> BitWriter {
        BitWriter::default()
    }

    /// Writes the `count` (≤ 32) low bits of `v`.
    pub fn put(&mut self, v: u64, count: u32) {
        debug_assert!(count <= 32);
        if count == 0 {
            return;
        }
        self.acc |= (v & ((1u64 << count) - 1)) << self.n;
        self.n += count;
        while self.n >= 8 {
            self.bytes.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    /// Writes up to 64 bits, 32 at a time.
    pub fn put_long(&mut self, v: u64, count: u32) {
        if count > 32 {
            self.put(v, 32);
            self.put(v >> 32, count - 32);
        } else {
            self.put(v, count);
        }
    }

    /// Rice code of `u` (≤ [`MAX_RICE_VALUE`]) with parameter `k` (< 32).
    pub fn rice(&mut self, u: u64, k: u32) {
        debug_assert!(u <= MAX_RICE_VALUE && k < 32);
        let q = u >> k;
        if q < ESCAPE {
            // q ones, then a zero.
            self.put_long((1u64 << q) - 1, q as u32 + 1);
            self.put(u, k);
        } else {
            self.put_long((1u64 << ESCAPE) - 1, ESCAPE as u32);
            let len = 64 - u.leading_zeros();
            self.put(len as u64, 6);
            self.put_long(u, len);
        }
    }

    /// Bits written so far.
    #[cfg(test)]
    pub fn bit_len(&self) -> usize {
        self.bytes.len() * 8 + self.n as usize
    }

    /// The bytes, the last one padded with zeros.
    pub fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.bytes.push(self.acc as u8);
        }
        self.bytes
    }
}

/// Bits a Rice code of `u` with parameter `k` takes.
pub fn rice_bits(u: u64, k: u32) -> u64 {
    let q = u >> k;
    if q < ESCAPE {
        q + 1 + k as u64
    } else {
        ESCAPE + 6 + (64 - u.leading_zeros()) as u64
    }
}

/// Reads bits written by [`BitWriter`]; running past the end is an error naming the byte.
pub struct BitReader<'a> {
    bytes: &'a [u8],
    /// Byte of the file where `bytes` starts (for messages).
    base: usize,
    pos: usize,
    acc: u64,
    n: u32,
}

impl<'a> BitReader<'a> {
    pub fn new(bytes: &'a [u8], base: usize) -> BitReader<'a> {
        BitReader { bytes, base, pos: 0, acc: 0, n: 0 }
    }

    fn refill(&mut self, what: &str) -> Result<()> {
        if self.pos >= self.bytes.len() {
            return Err(MocapError::Codec(format!(
                "truncated segment: expected {what} at byte {}, past the segment's end",
                self.base + self.pos
            )));
        }
        self.acc |= (self.bytes[self.pos] as u64) << self.n;
        self.pos += 1;
        self.n += 8;
        Ok(())
    }

    /// Tops the buffer up to at least 56 bits when the bytes are there: eight bytes at once
    /// away from the end. Bits above `n` may already hold the next bytes (loaded again at the
    /// same place by the next top-up, so OR-ing them twice changes nothing).
    #[inline]
    fn top_up(&mut self) {
        if self.pos + 8 <= self.bytes.len() {
            let w = u64::from_le_bytes(self.bytes[self.pos..self.pos + 8].try_into().expect("8 bytes"));
            self.acc |= w << self.n;
            let take = (63 - self.n) / 8;
            self.pos += take as usize;
            self.n += take * 8;
        } else {
            while self.n <= 56 && self.pos < self.bytes.len() {
                self.acc |= (self.bytes[self.pos] as u64) << self.n;
                self.pos += 1;
                self.n += 8;
            }
        }
    }

    /// Reads `count` (≤ 32) bits.
    pub fn get(&mut self, count: u32, what: &str) -> Result<u64> {
        debug_assert!(count <= 32);
        if self.n < count {
            self.top_up();
            while self.n < count {
                self.refill(what)?;
            }
        }
        let v = self.acc & ((1u64 << count) - 1);
        self.acc >>= count;
        self.n -= count;
        Ok(v)
    }

    /// Reads up to 64 bits.
    pub fn get_long(&mut self, count: u32, what: &str) -> Result<u64> {
        if count > 32 {
            let lo = self.get(32, what)?;
            Ok(lo | (self.get(count - 32, what)? << 32))
        } else {
            self.get(count, what)
        }
    }

    /// Where the reader stands, to [`BitReader::resume`] later on the same bytes.
    pub fn state(&self) -> (usize, u64, u32) {
        (self.pos, self.acc, self.n)
    }

    /// A reader over `bytes` at a `state` an earlier reader over the same bytes returned.
    pub fn resume(bytes: &'a [u8], base: usize, (pos, acc, n): (usize, u64, u32)) -> BitReader<'a> {
        BitReader { bytes, base, pos: pos.min(bytes.len()), acc, n }
    }

    /// Bytes read so far.
    pub fn bytes_used(&self) -> usize {
        self.pos - self.n as usize / 8
    }

    /// Reads a Rice code of parameter `k`: the unary part is counted a word at a time.
    #[inline]
    pub fn rice(&mut self, k: u32, what: &str) -> Result<u64> {
        if self.n < 56 {
            self.top_up();
        }
        // Fast path: the whole code is in the buffer.
        let ones = self.acc.trailing_ones();
        if (ones as u64) < ESCAPE && ones + 1 + k <= self.n {
            let v = ((ones as u64) << k) | ((self.acc >> (ones + 1)) & ((1u64 << k) - 1));
            let used = ones + 1 + k;
            self.acc = if used >= 64 { 0 } else { self.acc >> used };
            self.n -= used;
            return Ok(v);
        }
        self.rice_slow(k, what)
    }

    #[cold]
    fn rice_slow(&mut self, k: u32, what: &str) -> Result<u64> {
        let mut q = 0;
        while q < ESCAPE {
            if self.n == 0 {
                self.refill(what)?;
                // Top up to a few bytes when they are there (fewer refills on long runs).
                while self.n <= 48 && self.pos < self.bytes.len() {
                    self.acc |= (self.bytes[self.pos] as u64) << self.n;
                    self.pos += 1;
                    self.n += 8;
                }
            }
            let ones = self.acc.trailing_ones().min(self.n) as u64;
            if q + ones < ESCAPE && ones < self.n as u64 {
                // A zero ends the unary part.
                self.acc >>= ones + 1;
                self.n -= ones as u32 + 1;
                return Ok(((q + ones) << k) | self.get(k, what)?);
            }
            let take = ones.min(ESCAPE - q);
            self.acc >>= take;
            self.n -= take as u32;
            q += take;
        }
        let len = self.get(6, what)? as u32;
        if len > 42 {
            return Err(MocapError::Codec(format!(
                "{what} near byte {}: escaped value of {len} bits, at most 42 allowed",
                self.base + self.pos
            )));
        }
        self.get_long(len, what)
    }
}

/// Zig-zag map of a signed value to an unsigned one (0, -1, 1, -2, … → 0, 1, 2, 3, …).
pub fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

pub fn unzigzag(u: u64) -> i64 {
    ((u >> 1) as i64) ^ -((u & 1) as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn rice_codes_round_trip_including_escapes_and_count_their_bits() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let values: Vec<(u64, u32)> = (0..2000)
            .map(|i| {
                let k = rng.random_range(0..20u32);
                let u = match i % 3 {
                    0 => rng.random_range(0..(4u64 << k)),
                    1 => rng.random_range(0..=MAX_RICE_VALUE),
                    _ => rng.random_range(0..64),
                };
                (u, k)
            })
            .collect();
        let mut w = BitWriter::new();
        let mut bits = 0;
        for &(u, k) in &values {
            w.rice(u, k);
            bits += rice_bits(u, k);
            w.put(5, 3);
            bits += 3;
        }
        assert_eq!(w.bit_len() as u64, bits);
        let bytes = w.finish();
        let mut r = BitReader::new(&bytes, 0);
        for &(u, k) in &values {
            assert_eq!(r.rice(k, "value").unwrap(), u);
            assert_eq!(r.get(3, "tag").unwrap(), 5);
        }
        // Past the end: an error, not a panic.
        let e = BitReader::new(&bytes[..3], 100).rice(0, "value");
        assert!(values[0].0 >> values[0].1 < 3 || e.is_err());
        let mut r = BitReader::new(&[0xff, 0xff, 0xff, 0xff], 40);
        let e = r.rice(2, "residual").unwrap_err().to_string();
        assert!(e.contains("residual") && e.contains("byte 44"), "{e}");
        for v in [0i64, 1, -1, 5, -6, 1 << 40, -(1 << 40)] {
            assert_eq!(unzigzag(zigzag(v)), v);
        }
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
    }
}
