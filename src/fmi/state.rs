//! A tiny little-endian codec for serialized FMU states.

#[derive(Default)]
pub struct StateWriter {
    pub buf: Vec<u8>,
}

impl StateWriter {
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn i32(&mut self, v: i32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn bool(&mut self, v: bool) {
        self.buf.push(v as u8);
    }
    pub fn bytes(&mut self, v: &[u8]) {
        self.u64(v.len() as u64);
        self.buf.extend_from_slice(v);
    }
    pub fn str(&mut self, v: &str) {
        self.bytes(v.as_bytes());
    }
    pub fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.f64(*x));
    }
    pub fn usizes(&mut self, v: &[usize]) {
        self.u64(v.len() as u64);
        v.iter().for_each(|x| self.u64(*x as u64));
    }
}

pub struct StateReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> StateReader<'a> {
    pub fn new(buf: &'a [u8]) -> Self {
        StateReader { buf, pos: 0 }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.buf.len() - self.pos < n {
            return Err(format!("serialized FMU state truncated at byte {} (needs {n} more)", self.pos));
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    pub fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    pub fn i32(&mut self) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    pub fn bool(&mut self) -> Result<bool, String> {
        match self.take(1)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!("serialized FMU state: {b} is not a boolean")),
        }
    }
    /// A length, checked against the bytes left (each element needs at least `unit` bytes).
    fn len(&mut self, unit: usize) -> Result<usize, String> {
        let n = self.u64()?;
        let left = (self.buf.len() - self.pos) as u64;
        if n.saturating_mul(unit as u64) > left {
            return Err(format!("serialized FMU state: a length of {n} exceeds the {left} bytes left"));
        }
        Ok(n as usize)
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = self.len(1)?;
        self.take(n)
    }
    pub fn str(&mut self) -> Result<String, String> {
        String::from_utf8(self.bytes()?.to_vec()).map_err(|_| "serialized FMU state: a string is not UTF-8".to_string())
    }
    pub fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.len(8)?;
        (0..n).map(|_| self.f64()).collect()
    }
    pub fn usizes(&mut self) -> Result<Vec<usize>, String> {
        let n = self.len(8)?;
        (0..n).map(|_| self.u64().map(|v| v as usize)).collect()
    }
    pub fn finish(&self) -> Result<(), String> {
        if self.pos == self.buf.len() { Ok(()) } else { Err(format!("serialized FMU state: {} bytes left over", self.buf.len() - self.pos)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn round_trip_and_truncation() {
        let mut w = StateWriter::default();
        w.u64(7);
        w.f64(-1.5);
        w.i32(-3);
        w.bool(true);
        w.str("héllo");
        w.f64s(&[1.0, f64::MAX]);
        w.usizes(&[4, 5]);
        let mut r = StateReader::new(&w.buf);
        assert_eq!(r.u64().unwrap(), 7);
        assert_eq!(r.f64().unwrap(), -1.5);
        assert_eq!(r.i32().unwrap(), -3);
        assert!(r.bool().unwrap());
        assert_eq!(r.str().unwrap(), "héllo");
        assert_eq!(r.f64s().unwrap(), vec![1.0, f64::MAX]);
        assert_eq!(r.usizes().unwrap(), vec![4, 5]);
        r.finish().unwrap();
        let cut = &w.buf[..w.buf.len() - 3];
        let mut r = StateReader::new(cut);
        let all = (|| -> Result<(), String> {
            r.u64()?;
            r.f64()?;
            r.i32()?;
            r.bool()?;
            r.str()?;
            r.f64s()?;
            r.usizes()?;
            Ok(())
        })();
        assert!(all.is_err());
        // A huge length is refused before allocating.
        let mut w = StateWriter::default();
        w.u64(u64::MAX);
        assert!(StateReader::new(&w.buf).f64s().is_err());
    }
}
