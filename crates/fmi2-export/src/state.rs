//! FMU-state byte format: little-endian, length-checked writer/reader and the
//! versioned, checksummed envelope used by fmi2SerializeFMUstate /
//! fmi2DeSerializeFMUstate.
//!
//! Envelope (all integers little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `b"FMI2RSST"` |
//! | 4 | format version ([`FORMAT_VERSION`]) |
//! | 4 + n | GUID of the model (u32 length + UTF-8) |
//! | 8 | payload length |
//! | len | payload (export-layer fields, then `VariableStore::write_state`, then `FmuModel::write_state`) |
//! | 8 | FNV-1a 64 checksum over every preceding byte |
//!
//! FNV-1a detects every single-byte change: each round is a bijection of the
//! running hash, so two buffers differing in one byte never hash alike.

use std::fmt;

/// Magic bytes opening every serialized FMU state.
pub const MAGIC: &[u8; 8] = b"FMI2RSST";
/// Version of the envelope and of the export layer's own payload fields.
pub const FORMAT_VERSION: u32 = 1;

/// Why an FMU-state buffer could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum StateError {
    /// The buffer ended while reading `what`.
    Truncated {
        what: &'static str,
        needed: usize,
        available: usize,
    },
    /// The buffer does not start with [`MAGIC`].
    BadMagic,
    /// The buffer was written by an unsupported format version.
    UnsupportedVersion(u32),
    /// The buffer belongs to another model (or another interface version).
    GuidMismatch { expected: String, found: String },
    /// The declared payload length disagrees with the buffer size.
    LengthMismatch { declared: u64, available: usize },
    /// The checksum does not match the content.
    Checksum { stored: u64, computed: u64 },
    /// Bytes left over after everything was read.
    TrailingBytes(usize),
    /// A boolean byte other than 0 or 1.
    InvalidBool(u8),
    /// A string that is not UTF-8.
    InvalidUtf8,
    /// Any other invalid content (e.g. a model-specific consistency check).
    Invalid(String),
}

impl StateError {
    /// A model-specific validation failure.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }
}

impl fmt::Display for StateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated {
                what,
                needed,
                available,
            } => {
                write!(f, "FMU state truncated: {what} needs {needed} bytes, {available} left")
            }
            Self::BadMagic => f.write_str("not a serialized FMU state of this export layer (bad magic bytes)"),
            Self::UnsupportedVersion(v) => {
                write!(
                    f,
                    "unsupported FMU state format version {v} (this FMU reads version {FORMAT_VERSION})"
                )
            }
            Self::GuidMismatch { expected, found } => {
                write!(
                    f,
                    "FMU state belongs to another model: GUID {found:?}, expected {expected:?}"
                )
            }
            Self::LengthMismatch { declared, available } => {
                write!(
                    f,
                    "FMU state payload length {declared} does not match the {available} bytes available"
                )
            }
            Self::Checksum { stored, computed } => {
                write!(
                    f,
                    "FMU state checksum mismatch (stored {stored:#018x}, computed {computed:#018x}): corrupt buffer"
                )
            }
            Self::TrailingBytes(n) => write!(f, "FMU state has {n} unexpected trailing bytes"),
            Self::InvalidBool(b) => write!(f, "FMU state holds invalid boolean byte {b}"),
            Self::InvalidUtf8 => f.write_str("FMU state holds a string that is not UTF-8"),
            Self::Invalid(m) => write!(f, "invalid FMU state: {m}"),
        }
    }
}

impl std::error::Error for StateError {}

/// FNV-1a, 64 bit.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Appends little-endian values to a byte buffer.
#[derive(Debug, Default, Clone)]
pub struct StateWriter {
    buf: Vec<u8>,
}

impl StateWriter {
    pub fn new() -> Self {
        Self::default()
    }
    pub fn f64(&mut self, value: f64) {
        self.buf.extend_from_slice(&value.to_bits().to_le_bytes());
    }
    pub fn i32(&mut self, value: i32) {
        self.buf.extend_from_slice(&value.to_le_bytes());
    }
    pub fn u32(&mut self, value: u32) {
        self.buf.extend_from_slice(&value.to_le_bytes());
    }
    pub fn u64(&mut self, value: u64) {
        self.buf.extend_from_slice(&value.to_le_bytes());
    }
    pub fn u8(&mut self, value: u8) {
        self.buf.push(value);
    }
    pub fn bool(&mut self, value: bool) {
        self.buf.push(u8::from(value));
    }
    /// A length-prefixed (u32) UTF-8 string.
    pub fn str(&mut self, value: &str) {
        let len = u32::try_from(value.len()).expect("string longer than 4 GiB in an FMU state");
        self.u32(len);
        self.buf.extend_from_slice(value.as_bytes());
    }
    /// Raw bytes, no length prefix.
    pub fn bytes(&mut self, value: &[u8]) {
        self.buf.extend_from_slice(value);
    }
    pub fn len(&self) -> usize {
        self.buf.len()
    }
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }
    pub fn as_bytes(&self) -> &[u8] {
        &self.buf
    }
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }
}

/// Reads what a [`StateWriter`] wrote; every read is bounds-checked.
#[derive(Debug, Clone)]
pub struct StateReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> StateReader<'a> {
    pub fn new(buf: &'a [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// `n` raw bytes.
    pub fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], StateError> {
        let available = self.remaining();
        if n > available {
            return Err(StateError::Truncated {
                what,
                needed: n,
                available,
            });
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &'static str) -> Result<[u8; N], StateError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }

    pub fn f64(&mut self) -> Result<f64, StateError> {
        Ok(f64::from_bits(u64::from_le_bytes(self.array("f64")?)))
    }
    pub fn i32(&mut self) -> Result<i32, StateError> {
        Ok(i32::from_le_bytes(self.array("i32")?))
    }
    pub fn u32(&mut self) -> Result<u32, StateError> {
        Ok(u32::from_le_bytes(self.array("u32")?))
    }
    pub fn u64(&mut self) -> Result<u64, StateError> {
        Ok(u64::from_le_bytes(self.array("u64")?))
    }
    pub fn u8(&mut self) -> Result<u8, StateError> {
        Ok(self.array::<1>("u8")?[0])
    }
    pub fn bool(&mut self) -> Result<bool, StateError> {
        match self.array::<1>("bool")?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(StateError::InvalidBool(b)),
        }
    }
    /// A length-prefixed UTF-8 string.
    pub fn str(&mut self) -> Result<&'a str, StateError> {
        let len = self.u32()? as usize;
        let bytes = self.take(len, "string")?;
        std::str::from_utf8(bytes).map_err(|_| StateError::InvalidUtf8)
    }
    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.pos
    }
    /// Error unless everything was read.
    pub fn finish(&self) -> Result<(), StateError> {
        match self.remaining() {
            0 => Ok(()),
            n => Err(StateError::TrailingBytes(n)),
        }
    }
}

/// Wrap `payload` into the envelope for the model with this GUID.
pub fn seal(guid: &str, payload: &[u8]) -> Vec<u8> {
    let mut w = StateWriter {
        buf: Vec::with_capacity(payload.len() + guid.len() + 40),
    };
    w.bytes(MAGIC);
    w.u32(FORMAT_VERSION);
    w.str(guid);
    w.u64(payload.len() as u64);
    w.bytes(payload);
    let sum = fnv1a64(w.as_bytes());
    w.u64(sum);
    w.into_bytes()
}

/// Check the envelope of `buf` for the model with this GUID and return its payload.
pub fn open<'a>(guid: &str, buf: &'a [u8]) -> Result<&'a [u8], StateError> {
    let mut r = StateReader::new(buf);
    if r.take(MAGIC.len(), "magic bytes")? != MAGIC {
        return Err(StateError::BadMagic);
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(StateError::UnsupportedVersion(version));
    }
    let found = r.str()?;
    if found != guid {
        return Err(StateError::GuidMismatch {
            expected: guid.to_string(),
            found: found.to_string(),
        });
    }
    let declared = r.u64()?;
    let available = r.remaining().saturating_sub(8);
    if declared != available as u64 {
        return Err(StateError::LengthMismatch { declared, available });
    }
    let payload = r.take(available, "payload")?;
    let covered = buf.len() - r.remaining();
    let stored = r.u64()?;
    r.finish()?;
    let computed = fnv1a64(&buf[..covered]);
    if stored != computed {
        return Err(StateError::Checksum { stored, computed });
    }
    Ok(payload)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_values() {
        let mut w = StateWriter::new();
        w.f64(-0.0);
        w.f64(f64::NAN);
        w.i32(-7);
        w.bool(true);
        w.str("héllo");
        let bytes = w.into_bytes();
        let mut r = StateReader::new(&bytes);
        assert_eq!(r.f64().unwrap().to_bits(), (-0.0f64).to_bits());
        assert!(r.f64().unwrap().is_nan());
        assert_eq!(r.i32().unwrap(), -7);
        assert!(r.bool().unwrap());
        assert_eq!(r.str().unwrap(), "héllo");
        r.finish().unwrap();
        assert!(matches!(r.u8(), Err(StateError::Truncated { .. })));
    }

    #[test]
    fn envelope_rejects_every_single_byte_change() {
        let sealed = seal("guid-1", &[1, 2, 3, 4, 5]);
        assert_eq!(open("guid-1", &sealed).unwrap(), &[1, 2, 3, 4, 5]);
        for i in 0..sealed.len() {
            for bit in 0..8 {
                let mut b = sealed.clone();
                b[i] ^= 1 << bit;
                assert!(open("guid-1", &b).is_err(), "byte {i} bit {bit}");
            }
        }
        for n in 0..sealed.len() {
            assert!(open("guid-1", &sealed[..n]).is_err());
        }
        assert!(matches!(open("guid-2", &sealed), Err(StateError::GuidMismatch { .. })));
        let mut longer = sealed.clone();
        longer.push(0);
        assert!(open("guid-1", &longer).is_err());
    }

    #[test]
    fn invalid_bool_and_utf8() {
        assert_eq!(StateReader::new(&[2]).bool(), Err(StateError::InvalidBool(2)));
        assert_eq!(
            StateReader::new(&[1, 0, 0, 0, 0xff]).str(),
            Err(StateError::InvalidUtf8)
        );
    }
}
