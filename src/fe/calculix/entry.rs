//! One `row column value` line of ccx's matrix output, read from its bytes without the general
//! float parser when the value is exactly representable by Clinger's fast path (Clinger 1990,
//! "How to read floating point numbers accurately": a decimal m·10^e with m ≤ 2^53 and |e| ≤ 22
//! is m × 10^e or m / 10^−e in one correctly rounded IEEE operation, so the result is bit-equal
//! to `str::parse::<f64>`). Anything else returns `None` and the caller takes the general path.

/// 10^0 … 10^22, each exact in f64 (5^22 < 2^53).
const POW10: [f64; 23] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22];

/// `row column value` with ASCII blanks around and between, or `None` (then: the general path).
pub(super) fn fast_entry(b: &[u8]) -> Option<((usize, usize), f64)> {
    let mut i = 0;
    let blanks = |i: &mut usize| {
        let start = *i;
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
        *i > start
    };
    blanks(&mut i);
    let r = index(b, &mut i)?;
    if !blanks(&mut i) {
        return None;
    }
    let c = index(b, &mut i)?;
    if !blanks(&mut i) {
        return None;
    }
    let v = value(b, &mut i)?;
    blanks(&mut i);
    (i == b.len()).then_some(((r, c), v))
}

/// An unsigned decimal index of at most 18 digits (no overflow of usize on 64 bits).
fn index(b: &[u8], i: &mut usize) -> Option<usize> {
    let start = *i;
    let mut x = 0usize;
    while *i < b.len() && b[*i].is_ascii_digit() && *i - start < 18 {
        x = 10 * x + (b[*i] - b'0') as usize;
        *i += 1;
    }
    (*i > start).then_some(x)
}

/// `[±]digits[.digits][(e|E)[±]digits]` with at most 19 significant-or-not digits in the
/// mantissa and the fast path's conditions, or `None`.
fn value(b: &[u8], i: &mut usize) -> Option<f64> {
    let negative = sign(b, i);
    let (mut m, mut digits, mut frac) = (0u64, 0usize, 0i32);
    while *i < b.len() && b[*i].is_ascii_digit() {
        m = m.wrapping_mul(10).wrapping_add((b[*i] - b'0') as u64);
        digits += 1;
        *i += 1;
    }
    if b.get(*i) == Some(&b'.') {
        *i += 1;
        while *i < b.len() && b[*i].is_ascii_digit() {
            m = m.wrapping_mul(10).wrapping_add((b[*i] - b'0') as u64);
            digits += 1;
            frac += 1;
            *i += 1;
        }
    }
    // 19 digits cannot overflow u64; more: the general path.
    if digits == 0 || digits > 19 {
        return None;
    }
    let mut e = 0i32;
    if matches!(b.get(*i), Some(b'e' | b'E')) {
        *i += 1;
        let neg_e = sign(b, i);
        let start = *i;
        while *i < b.len() && b[*i].is_ascii_digit() && *i - start < 4 {
            e = 10 * e + (b[*i] - b'0') as i32;
            *i += 1;
        }
        if *i == start {
            return None;
        }
        if neg_e {
            e = -e;
        }
    }
    let e = e - frac;
    let x = if m == 0 {
        0.0
    } else if m > 1 << 53 || e.unsigned_abs() > 22 {
        return None;
    } else if e >= 0 {
        m as f64 * POW10[e as usize]
    } else {
        m as f64 / POW10[(-e) as usize]
    };
    Some(if negative { -x } else { x })
}

/// An optional `+` or `-` at `i`, skipped; whether it was `-`.
fn sign(b: &[u8], i: &mut usize) -> bool {
    let s = b.get(*i).copied();
    if matches!(s, Some(b'-' | b'+')) {
        *i += 1;
    }
    s == Some(b'-')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_path_equals_the_standard_parser_bit_for_bit_or_declines() {
        // Independent reference: Rust's correctly rounded `str::parse::<f64>`.
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let (mut fast, mut declined) = (0, 0);
        for k in 0..200_000 {
            let mant = next() % 100_000_000_000_000;
            let exp = (next() % 61) as i32 - 30;
            let sign = if next() % 2 == 0 { "-" } else { "" };
            let text = match k % 4 {
                0 => format!("{sign}{}.{:013}e{:+03}", mant / 10_000_000_000_000 % 10, mant % 10_000_000_000_000, exp),
                1 => format!("{sign}{}.{:013}E{exp}", mant % 10, mant / 10),
                2 => format!("{sign}{mant}"),
                _ => format!("{sign}0.{mant:014}"),
            };
            let line = format!("  {} {}  {text}\r", k + 1, 2 * k + 3);
            let want = text.parse::<f64>().unwrap();
            match fast_entry(line.as_bytes()) {
                Some(((r, c), v)) => {
                    assert_eq!((r, c), (k + 1, 2 * k + 3), "{line}");
                    assert_eq!(v.to_bits(), want.to_bits(), "{text}");
                    fast += 1;
                }
                None => declined += 1,
            }
        }
        // Both paths exercised (exponents beyond ±22 after the fraction's shift decline).
        assert!(fast > 100_000 && declined > 1000, "fast {fast}, declined {declined}");
        for bad in ["1 1", "1 1 2.0 3", "1x 1 2.0", "1 1 e5", "1 1 2.0e", "1 1 .", "11 2.0", "1 1 1.0000000000000000000001"] {
            assert_eq!(fast_entry(bad.as_bytes()), None, "{bad}");
        }
        assert_eq!(fast_entry(b"3 4 -0.0").map(|e| e.1.to_bits()), Some((-0.0f64).to_bits()));
    }
}
