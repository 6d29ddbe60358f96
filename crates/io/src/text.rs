//! Text from bytes, written once: every reader of a text file or an uploaded text (BVH, ASF/AMC, face
//! curves and TextGrids, scripts, the studio's uploads) decodes UTF-8 here and words the error its own
//! way from the position [`NotUtf8`] gives.

use std::fmt;

/// Where bytes stop being UTF-8: the byte offset, its 1-based line and the byte found there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotUtf8 {
    /// Offset of the first invalid byte.
    pub offset: usize,
    /// 1-based line of that byte (lines counted by `\n`).
    pub line: usize,
    /// The byte found there.
    pub byte: u8,
}

impl fmt::Display for NotUtf8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: expected UTF-8 text, found byte 0x{:02x} at offset {}", self.line, self.byte, self.offset)
    }
}

impl std::error::Error for NotUtf8 {}

/// The bytes as a `String`, or where they stop being UTF-8 (no copy on success).
pub fn utf8(bytes: Vec<u8>) -> Result<String, NotUtf8> {
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        NotUtf8 { offset, line: 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count(), byte: bytes[offset] }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_line_offset_and_byte() {
        assert_eq!(utf8(b"ok\n".to_vec()).unwrap(), "ok\n");
        let e = utf8(b"a\nb\n\xffc".to_vec()).unwrap_err();
        assert_eq!(e, NotUtf8 { offset: 4, line: 3, byte: 0xff });
        assert_eq!(e.to_string(), "line 3: expected UTF-8 text, found byte 0xff at offset 4");
    }
}
