//! The codec of serialized FMU states: checked, versioned, little-endian, and refusing
//! anything it cannot read exactly.
//!
//! Layout: the 8-byte [`MAGIC`], the format version ([`FORMAT_VERSION`], `u16`), the model's
//! own state version (`u16`, [`CoSimModel::STATE_VERSION`](crate::fmi::CoSimModel::STATE_VERSION)),
//! then the fields in the order the shell and the model write them. Lengths are `u64` counts,
//! checked against the bytes left before anything is allocated; every narrowing conversion is
//! checked (`u8::try_from`, `usize::try_from`), never `as`. A state must be read to its last
//! byte. The states of earlier builds (magic `PCFMI2S1`, no version) are refused by name.
use crate::error::{Error, Result};

/// The first bytes of every serialized state.
pub const MAGIC: [u8; 8] = *b"PCFMUSTA";
/// The layout of the shell's part. Version 1 was the unversioned `PCFMI2S1` layout.
pub const FORMAT_VERSION: u16 = 2;
/// The header of version 1 (earlier builds).
const LEGACY_MAGIC: [u8; 8] = *b"PCFMI2S1";
/// Bytes before the first field.
pub const HEADER_LEN: usize = MAGIC.len() + 2 + 2;

fn refused(message: impl std::fmt::Display) -> Error {
    Error::input(format!("serialized FMU state: {message}"))
}

/// Writes a state. Counts are written as `u64` (a `usize` always fits).
pub struct StateWriter {
    buf: Vec<u8>,
}

impl StateWriter {
    /// A state of the current format, with the model's state version.
    pub fn new(model_version: u16) -> Self {
        let mut buf = Vec::with_capacity(256);
        buf.extend_from_slice(&MAGIC);
        buf.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        buf.extend_from_slice(&model_version.to_le_bytes());
        StateWriter { buf }
    }
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn usize(&mut self, v: usize) {
        self.u64(u64::try_from(v).expect("a usize fits in a u64 on the supported targets"));
    }
    pub fn f64(&mut self, v: f64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn i32(&mut self, v: i32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    pub fn str(&mut self, v: &str) {
        self.usize(v.len());
        self.buf.extend_from_slice(v.as_bytes());
    }
    pub fn f64s(&mut self, v: &[f64]) {
        self.usize(v.len());
        v.iter().for_each(|x| self.f64(*x));
    }
    pub fn usizes(&mut self, v: &[usize]) {
        self.usize(v.len());
        v.iter().for_each(|x| self.usize(*x));
    }
    /// A count of items that follow (each read back with [`StateReader::count`]).
    pub fn count(&mut self, n: usize) {
        self.usize(n);
    }
}

/// Reads a state written by [`StateWriter`]; every method refuses rather than truncates.
pub struct StateReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> StateReader<'a> {
    /// Checks the header: the magic, the format version and the model's state version.
    pub fn new(bytes: &'a [u8], model_version: u16) -> Result<Self> {
        if bytes.len() >= LEGACY_MAGIC.len() && bytes[..LEGACY_MAGIC.len()] == LEGACY_MAGIC {
            return Err(refused(format!(
                "this is a version-1 state of an earlier build; this FMU reads format version {FORMAT_VERSION} only (save the state again with this FMU)"
            )));
        }
        if bytes.len() < HEADER_LEN || bytes[..MAGIC.len()] != MAGIC {
            return Err(refused("the bytes are not a serialized state of this FMU (bad header)"));
        }
        let mut r = StateReader { buf: bytes, pos: MAGIC.len() };
        let format = r.u16()?;
        if format != FORMAT_VERSION {
            return Err(refused(format!("format version {format} is not readable by this FMU, which reads version {FORMAT_VERSION}")));
        }
        let model = r.u16()?;
        if model != model_version {
            return Err(refused(format!("the model part has version {model}, this FMU reads version {model_version}")));
        }
        Ok(r)
    }

    fn left(&self) -> usize {
        self.buf.len() - self.pos
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        if self.left() < N {
            return Err(refused(format!("truncated at byte {} (needs {N} more, {} left)", self.pos, self.left())));
        }
        let mut a = [0u8; N];
        a.copy_from_slice(&self.buf[self.pos..self.pos + N]);
        self.pos += N;
        Ok(a)
    }
    fn u16(&mut self) -> Result<u16> {
        Ok(u16::from_le_bytes(self.take()?))
    }
    pub fn u8(&mut self) -> Result<u8> {
        Ok(self.take::<1>()?[0])
    }
    pub fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take()?))
    }
    pub fn usize(&mut self) -> Result<usize> {
        let at = self.pos;
        let v = self.u64()?;
        usize::try_from(v).map_err(|_| refused(format!("the count {v} at byte {at} does not fit this platform")))
    }
    pub fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take()?))
    }
    pub fn i32(&mut self) -> Result<i32> {
        Ok(i32::from_le_bytes(self.take()?))
    }
    pub fn bool(&mut self) -> Result<bool> {
        let at = self.pos;
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(refused(format!("byte {at}: {b} is not a boolean"))),
        }
    }
    /// A count of items that each take at least `min_bytes`, checked against the bytes left.
    pub fn count(&mut self, min_bytes: usize) -> Result<usize> {
        let at = self.pos;
        let n = self.usize()?;
        let need = n.checked_mul(min_bytes.max(1));
        if need.is_none_or(|need| need > self.left()) {
            return Err(refused(format!("byte {at}: a count of {n} exceeds the {} bytes left", self.left())));
        }
        Ok(n)
    }
    pub fn str(&mut self) -> Result<String> {
        let n = self.count(1)?;
        let at = self.pos;
        let bytes = self.buf[self.pos..self.pos + n].to_vec();
        self.pos += n;
        String::from_utf8(bytes).map_err(|_| refused(format!("byte {at}: a string is not UTF-8")))
    }
    pub fn f64s(&mut self) -> Result<Vec<f64>> {
        let n = self.count(8)?;
        (0..n).map(|_| self.f64()).collect()
    }
    pub fn usizes(&mut self) -> Result<Vec<usize>> {
        let n = self.count(8)?;
        (0..n).map(|_| self.usize()).collect()
    }
    /// The whole state has been read.
    pub fn finish(&self) -> Result<()> {
        if self.left() == 0 { Ok(()) } else { Err(refused(format!("{} bytes left over after the last field", self.left()))) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<u8> {
        let mut w = StateWriter::new(3);
        w.u64(7);
        w.f64(-1.5);
        w.i32(-3);
        w.bool(true);
        w.u8(200);
        w.str("héllo");
        w.f64s(&[1.0, f64::MAX, f64::MIN_POSITIVE]);
        w.usizes(&[4, 5]);
        w.into_bytes()
    }

    fn read_all(bytes: &[u8]) -> Result<()> {
        let mut r = StateReader::new(bytes, 3)?;
        assert_eq!(r.u64()?, 7);
        assert_eq!(r.f64()?, -1.5);
        assert_eq!(r.i32()?, -3);
        assert!(r.bool()?);
        assert_eq!(r.u8()?, 200);
        assert_eq!(r.str()?, "héllo");
        assert_eq!(r.f64s()?, vec![1.0, f64::MAX, f64::MIN_POSITIVE]);
        assert_eq!(r.usizes()?, vec![4, 5]);
        r.finish()
    }

    #[test]
    fn a_round_trip_is_exact() {
        read_all(&sample()).unwrap();
    }

    #[test]
    fn every_truncation_and_an_extension_are_refused() {
        let bytes = sample();
        for cut in 0..bytes.len() {
            let e = read_all(&bytes[..cut]).unwrap_err();
            assert_eq!(e.kind(), crate::error::ErrorKind::Input);
            assert!(e.message().starts_with("serialized FMU state: "), "{e}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(read_all(&longer).unwrap_err().message().contains("1 bytes left over"));
    }

    #[test]
    fn other_versions_and_foreign_bytes_are_refused_with_the_reason() {
        let bytes = sample();
        let mut format = bytes.clone();
        format[MAGIC.len()] = 1;
        assert!(read_all(&format).unwrap_err().message().contains("format version 1 is not readable"));
        assert!(StateReader::new(&bytes, 4).err().unwrap().message().contains("the model part has version 3, this FMU reads version 4"));
        let mut legacy = bytes.clone();
        legacy[..8].copy_from_slice(b"PCFMI2S1");
        assert!(read_all(&legacy).unwrap_err().message().contains("version-1 state of an earlier build"));
        assert!(read_all(b"not a state at all").unwrap_err().message().contains("bad header"));
    }

    #[test]
    fn corrupt_fields_are_refused_before_allocating() {
        let mut w = StateWriter::new(0);
        w.u64(u64::MAX);
        let bytes = w.into_bytes();
        assert!(StateReader::new(&bytes, 0).unwrap().f64s().unwrap_err().message().contains("exceeds"));
        let mut w = StateWriter::new(0);
        w.u8(2);
        let bytes = w.into_bytes();
        assert!(StateReader::new(&bytes, 0).unwrap().bool().unwrap_err().message().contains("not a boolean"));
        let mut w = StateWriter::new(0);
        w.count(usize::MAX);
        let bytes = w.into_bytes();
        assert!(StateReader::new(&bytes, 0).unwrap().count(8).is_err());
    }
}
