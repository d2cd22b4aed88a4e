//! FNV-1a, 64 bit: the one non-cryptographic hash of the workspace (table checksums,
//! sweep fingerprints and shard checksums). It detects accidental damage (truncation,
//! dropped rows, changed bytes), not deliberate tampering.

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// An incremental FNV-1a hasher.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(OFFSET)
    }
}

impl Fnv1a {
    /// Feeds bytes.
    pub fn update(&mut self, data: &[u8]) -> &mut Self {
        for &b in data {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(PRIME);
        }
        self
    }

    /// Feeds one part followed by a separator byte, so that ("ab", "c") and ("a", "bc")
    /// hash differently.
    pub fn part(&mut self, data: &[u8]) -> &mut Self {
        self.update(data).update(&[0xff])
    }

    /// The hash so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// FNV-1a of `data`.
pub fn fnv1a(data: &[u8]) -> u64 {
    Fnv1a::default().update(data).finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Published FNV-1a 64 test vectors.
    #[test]
    fn known_values() {
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
        let mut h = Fnv1a::default();
        h.part(b"ab").part(b"c");
        let mut g = Fnv1a::default();
        g.part(b"a").part(b"bc");
        assert_ne!(h.finish(), g.finish());
    }
}
