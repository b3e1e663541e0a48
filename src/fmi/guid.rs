//! A GUID derived from content: 128-bit FNV-1a of the model description rendered with an empty
//! guid, formatted like a UUID. Deterministic across builds and platforms (unlike
//! `DefaultHasher`), so the packager and the FMU binary agree when, and only when, they render
//! the same modelDescription.xml.

const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
const PRIME: u128 = 0x0000000001000000000000000000013B;

pub fn fnv1a128(bytes: &[u8]) -> u128 {
    bytes.iter().fold(OFFSET, |h, &b| (h ^ b as u128).wrapping_mul(PRIME))
}

/// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}` of the content hash.
pub fn from_content(bytes: &[u8]) -> String {
    let h = format!("{:032x}", fnv1a128(bytes));
    format!("{{{}-{}-{}-{}-{}}}", &h[0..8], &h[8..12], &h[12..16], &h[16..20], &h[20..32])
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn known_values_and_format() {
        // FNV-1a 128 of "" is the offset basis; of "a" the published test vector.
        assert_eq!(fnv1a128(b""), OFFSET);
        assert_eq!(fnv1a128(b"a"), 0xd228cb696f1a8caf78912b704e4a8964);
        let g = from_content(b"abc");
        assert_eq!(g.len(), 38);
        assert!(g.starts_with('{') && g.ends_with('}'));
        assert_ne!(from_content(b"abc"), from_content(b"abd"));
    }
}
