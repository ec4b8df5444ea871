//! Exact positive rationals with overflow detection: firing ratios are products
//! of rates, and a wrong answer from a wrapped integer would be worse than none.

/// A positive rational `num/den` in lowest terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ratio {
    pub num: u64,
    pub den: u64,
}

pub fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// `None` on overflow.
pub fn lcm(a: u64, b: u64) -> Option<u64> {
    if a == 0 || b == 0 {
        return Some(0);
    }
    (a / gcd(a, b)).checked_mul(b)
}

impl Ratio {
    pub const ONE: Ratio = Ratio { num: 1, den: 1 };

    /// `num/den` reduced; `None` if `den` is zero.
    pub fn new(num: u64, den: u64) -> Option<Ratio> {
        if den == 0 {
            return None;
        }
        let g = gcd(num, den).max(1);
        Some(Ratio {
            num: num / g,
            den: den / g,
        })
    }

    /// `self * p / c`, reduced; `None` on overflow or `c == 0`.
    pub fn scale(self, p: u64, c: u64) -> Option<Ratio> {
        let num = u128::from(self.num) * u128::from(p);
        let den = u128::from(self.den) * u128::from(c);
        if den == 0 {
            return None;
        }
        let g = gcd128(num, den).max(1);
        Some(Ratio {
            num: u64::try_from(num / g).ok()?,
            den: u64::try_from(den / g).ok()?,
        })
    }

    /// `self / other`.
    pub fn divided_by(self, other: Ratio) -> Option<Ratio> {
        self.scale(other.den, other.num)
    }
}

/// Orders by value (cross-multiplied in 128 bits, so never overflows). Agrees
/// with `==` for ratios in lowest terms, which is all that `new` and `scale` make.
impl Ord for Ratio {
    fn cmp(&self, other: &Ratio) -> std::cmp::Ordering {
        (u128::from(self.num) * u128::from(other.den))
            .cmp(&(u128::from(other.num) * u128::from(self.den)))
    }
}

impl PartialOrd for Ratio {
    fn partial_cmp(&self, other: &Ratio) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl std::fmt::Display for Ratio {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

fn gcd128(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_exact_and_reduced() {
        assert_eq!(Ratio::ONE.scale(10, 4), Ratio::new(5, 2));
        assert_eq!(Ratio::new(6, 4).unwrap(), Ratio { num: 3, den: 2 });
        assert_eq!(
            Ratio::new(3, 2)
                .unwrap()
                .divided_by(Ratio::new(3, 4).unwrap()),
            Ratio::new(2, 1)
        );
        assert_eq!(lcm(4, 6), Some(12));
    }

    #[test]
    fn overflow_is_reported_not_wrapped() {
        let big = Ratio::new(u64::MAX, 1).unwrap();
        assert_eq!(big.scale(3, 1), None);
        assert_eq!(lcm(u64::MAX, u64::MAX - 1), None);
    }
}
