//! Did-you-mean: the closest known name by edit distance.

/// Edit distance counting insertions, deletions, substitutions and swaps of
/// two neighbouring characters (optimal string alignment): `mvoe` is one edit
/// from `move`, as a typist would see it.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // Three rows: two back (for swaps), previous, current.
    let mut before: Vec<usize> = vec![0; b.len() + 1];
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 0..a.len() {
        cur[0] = i + 1;
        for j in 0..b.len() {
            let cost = usize::from(a[i] != b[j]);
            let mut d = (prev[j] + cost).min(prev[j + 1] + 1).min(cur[j] + 1);
            if i > 0 && j > 0 && a[i] == b[j - 1] && a[i - 1] == b[j] {
                d = d.min(before[j - 1] + 1);
            }
            cur[j + 1] = d;
        }
        std::mem::swap(&mut before, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// The candidate closest to `name`, if it is close enough to be a likely typo:
/// a case-insensitive match, a prefix of at least three characters (`RETURN` for
/// `RETURN_MODE`), or at most a third of the name's length in edits. Names of
/// one or two characters only match up to case.
pub fn did_you_mean<'a, I>(name: &str, candidates: I) -> Option<String>
where
    I: IntoIterator<Item = &'a str>,
{
    let length = name.chars().count();
    let limit = if length < 3 { 0 } else { (length / 3).max(1) };
    let lower = name.to_lowercase();
    let mut best: Option<(usize, &str)> = None;
    for cand in candidates {
        if cand == name {
            continue;
        }
        let cand_lower = cand.to_lowercase();
        let d = if cand_lower == lower {
            0
        } else if length >= 3 && cand_lower.starts_with(&lower) {
            1
        } else if cand.chars().count().abs_diff(length) > limit {
            // Each edit changes the length by one at most: too far, and
            // known without the distance (a check reports thousands).
            continue;
        } else {
            edit_distance(name, cand)
        };
        if d <= limit && best.is_none_or(|(bd, bc)| d < bd || (d == bd && cand < bc)) {
            best = Some((d, cand));
        }
    }
    best.map(|(_, c)| c.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances() {
        assert_eq!(edit_distance("move", "mvoe"), 1);
        assert_eq!(edit_distance("abc", "ca"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }

    #[test]
    fn suggestions() {
        let names = ["SEARCH_MODE", "AUTO_MODE", "RC_MODE"];
        assert_eq!(
            did_you_mean("SERCH_MODE", names).as_deref(),
            Some("SEARCH_MODE")
        );
        assert_eq!(
            did_you_mean("auto_mode", names).as_deref(),
            Some("AUTO_MODE")
        );
        assert_eq!(did_you_mean("XYZ", names), None);
        assert_eq!(
            did_you_mean("SEARCH", names).as_deref(),
            Some("SEARCH_MODE")
        );
        assert_eq!(
            did_you_mean("Master", ["MasterTeam", "SlaveTeam"]).as_deref(),
            Some("MasterTeam")
        );
        assert_eq!(did_you_mean("x", ["y", "X"]).as_deref(), Some("X"));
        assert_eq!(did_you_mean("x", ["y", "ab"]), None);
    }

    proptest::proptest! {
        /// What lets `did_you_mean` skip a candidate without the distance:
        /// it is never less than the difference of the lengths.
        #[test]
        fn the_distance_is_at_least_the_difference_of_the_lengths(
            a in "[a-cé]{0,8}",
            b in "[a-cé]{0,8}",
        ) {
            let lengths = a.chars().count().abs_diff(b.chars().count());
            proptest::prop_assert!(edit_distance(&a, &b) >= lengths);
        }
    }
}
