//! A fast, deterministic hasher for the checker's maps of names and ids (the
//! multiply-rotate hash that rustc uses, "FxHash"). The standard SipHash
//! resists collision attacks, which a checker of local files does not need,
//! and was a fifth of the checker's time on a large mission.
//!
//! Nothing may depend on the iteration order of these maps (it is not the
//! standard maps' either, which is random per process).

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

pub type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;
pub type FastSet<T> = HashSet<T, BuildHasherDefault<FastHasher>>;

#[derive(Clone, Copy, Default)]
pub struct FastHasher {
    hash: u64,
}

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;
/// 2^64 divided by the golden ratio, odd.
const FINISH: u64 = 0x9e_37_79_b9_7f_4a_7c_15;

impl FastHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.hash = (self.hash.rotate_left(5) ^ word).wrapping_mul(SEED);
    }
}

/// `bytes` as little-endian 64-bit words, the last one padded with zeros:
/// `each` gets a word and how many of its bytes are the text's (8 but for
/// a short last one), so that a hasher can tell "a" from "a\0".
#[inline]
pub(crate) fn le_words(bytes: &[u8], mut each: impl FnMut(u64, usize)) {
    let mut chunks = bytes.chunks_exact(8);
    for chunk in &mut chunks {
        let mut word = [0; 8];
        word.copy_from_slice(chunk);
        each(u64::from_le_bytes(word), 8);
    }
    let rest = chunks.remainder();
    if !rest.is_empty() {
        let mut word = [0; 8];
        word[..rest.len()].copy_from_slice(rest);
        each(u64::from_le_bytes(word), rest.len());
    }
}

impl Hasher for FastHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        le_words(bytes, |word, len| match len {
            8 => self.add(word),
            // The length keeps "a" and "a\0" apart.
            _ => self.add(word ^ ((len as u64) << 56)),
        });
    }

    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u16(&mut self, i: u16) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    /// The state mixed by one folded multiplication (the 128-bit product's
    /// halves xored, as foldhash and wyhash finish): a product's low bits
    /// depend only on its factors' low bits, and a table picks its bucket
    /// by the hash's low bits, so without it names differing only in their
    /// last characters (`a0` … `a99999`, generated names) share a few
    /// buckets and every lookup compares them all.
    #[inline]
    fn finish(&self) -> u64 {
        let product = u128::from(self.hash) * u128::from(FINISH);
        (product as u64) ^ ((product >> 64) as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    fn hash(value: impl Hash) -> u64 {
        BuildHasherDefault::<FastHasher>::default().hash_one(value)
    }

    #[test]
    fn equal_values_hash_alike_and_close_ones_apart() {
        assert_eq!(hash("Team12"), hash(String::from("Team12")));
        let names: Vec<String> = (0..1000).map(|i| format!("Team{i}")).collect();
        let hashes: HashSet<u64> = names.iter().map(hash).collect();
        assert_eq!(hashes.len(), names.len());
        assert_ne!(hash("a"), hash("a\0"));
        assert_ne!(hash((1u32, 2u32)), hash((2u32, 1u32)));
        let mut map: FastMap<&str, usize> = FastMap::default();
        for (i, n) in names.iter().enumerate() {
            map.insert(n, i);
        }
        assert!(names.iter().enumerate().all(|(i, n)| map[n.as_str()] == i));
    }

    /// A table picks its bucket by the hash's low bits: names that differ
    /// only at their end must spread over them, or every lookup compares
    /// them all (quadratic: a catalog element with 100,000 attributes took
    /// seconds to check for repeated names).
    #[test]
    fn names_differing_at_their_end_spread_over_the_low_bits() {
        let n = 1 << 16;
        for prefix in ["a", "S", "robot_", "a_rather_long_name_"] {
            let low: HashSet<u64> = (0..n)
                .map(|i| hash(format!("{prefix}{i}")) & 0xffff)
                .collect();
            assert!(low.len() > n / 2, "{prefix}: {} buckets of {n}", low.len());
            let bytes: HashSet<u64> = (0..n)
                .map(|i| hash(format!("{prefix}{i}").as_bytes()) & 0xffff)
                .collect();
            assert!(
                bytes.len() > n / 2,
                "{prefix}: {} buckets of {n}",
                bytes.len()
            );
        }
    }
}
