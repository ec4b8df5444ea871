//! The scenario's random message loss, as a function of the message rather
//! than of a running random stream.
//!
//! Two engines carry a mission's messages: the simulator, and the lock-step
//! coordinator that is the network of generated robots (`semo simulate
//! --engine c`). They must lose the same messages for a seed, yet they meet
//! the messages in different orders (the simulator robot by robot within an
//! instant, the coordinator as the processes' frames come), and a delayed
//! message reaches the coordinator later than it was sent. So a draw depends
//! only on the seed, the sender, the receiver, the message's key, and how
//! many messages of that key the sender sent that receiver before: the same
//! for both engines whatever the interleaving.

use std::collections::HashMap;

use rand_core::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

/// The draws of one run: per (sender, receiver, key), the messages so far.
#[derive(Clone, Debug)]
pub struct LossDraws {
    seed: u64,
    /// By the stream's hash; two streams with one hash share a count,
    /// the same way in every engine.
    sent: HashMap<u64, u64>,
}

impl LossDraws {
    pub fn new(seed: u64) -> Self {
        LossDraws {
            seed,
            sent: HashMap::new(),
        }
    }

    /// Whether the next message of `key` from `from` to `to` is lost, with
    /// `probability` (0 loses nothing and draws nothing, so a lossless link
    /// does not depend on how many messages came before).
    pub fn lost(&mut self, from: &str, to: &str, key: &str, probability: f64) -> bool {
        if probability <= 0.0 {
            return false;
        }
        let stream = stable_hash(self.seed, &[from, to, key]);
        let n = self.sent.entry(stream).or_insert(0);
        let mut draw = XorShiftRng::seed_from_u64(stream ^ n.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        *n += 1;
        // 53 bits: every value below 1 is exact as an f64.
        let uniform = (draw.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        uniform < probability
    }
}

/// FNV-1a over the seed and the length-prefixed parts: stable across
/// runs, platforms and Rust versions (the standard hasher promises none of
/// these), which replaying a seed needs.
fn stable_hash(seed: u64, parts: &[&str]) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01B3;
    let mut h: u64 = 0xCBF2_9CE4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(PRIME);
        }
    };
    eat(&seed.to_le_bytes());
    for part in parts {
        eat(&(part.len() as u64).to_le_bytes());
        eat(part.as_bytes());
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_depend_on_the_stream_not_on_the_interleaving() {
        let p = 0.5;
        let mut one = LossDraws::new(7);
        let a: Vec<bool> = (0..64)
            .map(|_| one.lost("ti", "ev", "T.COLOR", p))
            .collect();
        let b: Vec<bool> = (0..64)
            .map(|_| one.lost("ti", "tb", "T.COLOR", p))
            .collect();
        // The other order, interleaved with another stream.
        let mut two = LossDraws::new(7);
        let mut b2 = Vec::new();
        let mut a2 = Vec::new();
        for _ in 0..64 {
            b2.push(two.lost("ti", "tb", "T.COLOR", p));
            two.lost("tb", "ti", "T.OTHER", p);
            a2.push(two.lost("ti", "ev", "T.COLOR", p));
        }
        assert_eq!((a.clone(), b), (a2, b2));
        let lost = a.iter().filter(|l| **l).count();
        assert!((16..=48).contains(&lost), "{lost} of 64 lost at 0.5");
        let mut other_seed = LossDraws::new(8);
        let c: Vec<bool> = (0..64)
            .map(|_| other_seed.lost("ti", "ev", "T.COLOR", p))
            .collect();
        assert_ne!(a, c, "the seed draws the losses");
    }

    #[test]
    fn certain_and_impossible_losses() {
        let mut d = LossDraws::new(1);
        assert!((0..100).all(|_| d.lost("a", "b", "k", 1.0)));
        assert!((0..100).all(|_| !d.lost("a", "b", "k", 0.0)));
        assert!(d.sent.values().all(|n| *n == 100), "no draw at 0");
    }

    #[test]
    fn the_hash_is_stable() {
        // Fixed: a seed replays the same losses in every later version.
        assert_eq!(stable_hash(0, &[]), 0xA8C7_F832_281A_39C5);
    }
}
