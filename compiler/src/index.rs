//! Typed indices: a plan's index cannot be passed where a mode's is meant.
//!
//! The checker's IR keeps each team's plans, services, modes and robots in
//! vectors and names them by position; refinement does the same with a
//! robot's states and slots. A bare `u32` or `usize` for all of them let one
//! be used for another and made "not known yet" a magic `usize::MAX`. Each
//! kind of index is its own type, made by [`newtype_index!`], and "not known
//! yet" is an `Option`. The storage stays a `Vec` (the indices are dense,
//! from 0): `items[i.index()]`, or the owner's accessor (`Team::plan`).
//!
//! A macro of a few lines rather than an arena crate (`la-arena`,
//! `index_vec`): nothing here needs an arena's allocation or a new vector
//! type that every `Vec` user would have to learn, only distinct index types
//! with a conversion.

/// Declares `struct Name(u32)` with `Name::new(usize)` and `Name::index()`.
macro_rules! newtype_index {
    ($(#[$meta:meta])* $vis:vis struct $name:ident;) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        $vis struct $name(u32);

        impl $name {
            /// The index at position `index` of its vector.
            pub fn new(index: usize) -> Self {
                // A file is at most 16 MiB: no vector of its items comes near.
                Self(u32::try_from(index).expect("fewer than 2^32 items"))
            }

            /// Its position in its vector.
            pub fn index(self) -> usize {
                self.0 as usize
            }

            /// Every index of a vector of `len` items, in order.
            pub fn all(len: usize) -> impl DoubleEndedIterator<Item = Self> + ExactSizeIterator + Clone {
                (0..len).map(Self::new)
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                self.0.fmt(f)
            }
        }
    };
}

pub(crate) use newtype_index;
