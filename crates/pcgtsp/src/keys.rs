//! Order ideals as fixed-width bitset keys ([`Key`]), and the one place that picks the key
//! width for a number of clusters: [`with_key_width!`] runs code at the width that fits (64,
//! 128 or 256 clusters), and [`Keyed`] holds a value built at that width (a lattice, a DP).
//! Every width-generic structure goes through these, so a new width is added here alone.

/// The most clusters a key holds: orders with more get no lattice and no DP.
pub(crate) const MAX_KEY_CLUSTERS: usize = 256;

/// An ideal as a fixed-width bitset (`64·W` clusters).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub(crate) struct Key<const W: usize>(pub [u64; W]);

impl<const W: usize> Key<W> {
    #[inline]
    pub fn empty() -> Self {
        Key([0; W])
    }
    #[inline]
    pub fn contains(&self, c: usize) -> bool {
        self.0[c / 64] >> (c % 64) & 1 == 1
    }
    #[inline]
    pub fn with(mut self, c: usize) -> Self {
        self.0[c / 64] |= 1 << (c % 64);
        self
    }
    /// The clusters in the set, in increasing order.
    #[inline]
    pub fn ones(&self) -> impl Iterator<Item = usize> + '_ {
        crate::order::set_bits(&self.0)
    }
    #[inline]
    pub fn contains_all(&self, other: &Self) -> bool {
        (0..W).all(|i| other.0[i] & !self.0[i] == 0)
    }
}

/// A family of types indexed by the key width, such as `Lattice<W>` or `Dp<W>`.
pub(crate) trait ByWidth {
    /// The family's type at width `W`.
    type At<const W: usize>;
}

/// One value of a width-indexed family, at the width [`with_key_width!`] chose.
pub(crate) enum Keyed<F: ByWidth> {
    W1(F::At<1>),
    W2(F::At<2>),
    W4(F::At<4>),
}

/// `with_key_width!(clusters, |W, wrap| body)`: `Some(body)` with the constant `W` set to the
/// key width (in words) for `clusters` clusters, `None` above [`MAX_KEY_CLUSTERS`]. The
/// optional `wrap` names the [`Keyed`] variant of that width, so `wrap(Lattice::<W>::new(..))`
/// builds a `Keyed` value.
macro_rules! with_key_width {
    ($clusters:expr, |$width:ident $(, $wrap:ident)?| $body:expr) => {
        match $clusters {
            0..=64 => {
                const $width: usize = 1;
                $(let $wrap = $crate::keys::Keyed::W1;)?
                Some($body)
            }
            65..=128 => {
                const $width: usize = 2;
                $(let $wrap = $crate::keys::Keyed::W2;)?
                Some($body)
            }
            129..=$crate::keys::MAX_KEY_CLUSTERS => {
                const $width: usize = 4;
                $(let $wrap = $crate::keys::Keyed::W4;)?
                Some($body)
            }
            _ => None,
        }
    };
}
pub(crate) use with_key_width;

/// `on_keyed!(keyed, |value, wrap| body)`: `body` with `value` bound to the [`Keyed`] value
/// at whichever width it holds; the optional `wrap` names the variant of that width, so
/// `wrap(..)` builds another family's value at the same width.
macro_rules! on_keyed {
    ($keyed:expr, |$value:pat_param $(, $wrap:ident)?| $body:expr) => {
        match $keyed {
            $crate::keys::Keyed::W1($value) => {
                $(let $wrap = $crate::keys::Keyed::W1;)?
                $body
            }
            $crate::keys::Keyed::W2($value) => {
                $(let $wrap = $crate::keys::Keyed::W2;)?
                $body
            }
            $crate::keys::Keyed::W4($value) => {
                $(let $wrap = $crate::keys::Keyed::W4;)?
                $body
            }
        }
    };
}
pub(crate) use on_keyed;
