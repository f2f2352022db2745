//! Transcendental functions that give the same bits on every platform.
//!
//! `f64::sin` and its kin call the platform's maths library: glibc natively, a port of musl's
//! in wasm32. The two differ in the last bit now and then, and a solver's choices (which corner
//! a chain link tries, which move a search accepts) can turn on that bit, so the page and the
//! CLI found different routes for the same nest, seed and limit. The `libm` crate is the same
//! Rust code everywhere; every crate that computes routes, reads files or prices moves uses it
//! through [`Libm`] (basic arithmetic and `sqrt` are exactly rounded by IEEE 754 already).
//!
//! ```
//! use cutroute_geometry::float::Libm;
//! assert_eq!(0.5f64.sin_libm(), libm::sin(0.5));
//! assert_eq!(1.0f64.atan2_libm(1.0), std::f64::consts::FRAC_PI_4);
//! ```

/// `f64` maths by the `libm` crate: one result per argument on every target.
pub trait Libm {
    /// The sine.
    fn sin_libm(self) -> f64;
    /// The cosine.
    fn cos_libm(self) -> f64;
    /// Sine and cosine.
    fn sin_cos_libm(self) -> (f64, f64);
    /// The tangent.
    fn tan_libm(self) -> f64;
    /// The arcsine.
    fn asin_libm(self) -> f64;
    /// The arccosine.
    fn acos_libm(self) -> f64;
    /// The arctangent.
    fn atan_libm(self) -> f64;
    /// `self.atan2(x)`: the angle of (x, self).
    fn atan2_libm(self, x: f64) -> f64;
    /// e to the power of `self`.
    fn exp_libm(self) -> f64;
    /// √(self² + other²) without overflow.
    fn hypot_libm(self, other: f64) -> f64;
    /// `self` to the power `n`.
    fn powf_libm(self, n: f64) -> f64;
}

impl Libm for f64 {
    fn sin_libm(self) -> f64 {
        ::libm::sin(self)
    }
    fn cos_libm(self) -> f64 {
        ::libm::cos(self)
    }
    fn sin_cos_libm(self) -> (f64, f64) {
        ::libm::sincos(self)
    }
    fn tan_libm(self) -> f64 {
        ::libm::tan(self)
    }
    fn asin_libm(self) -> f64 {
        ::libm::asin(self)
    }
    fn acos_libm(self) -> f64 {
        ::libm::acos(self)
    }
    fn atan_libm(self) -> f64 {
        ::libm::atan(self)
    }
    fn atan2_libm(self, x: f64) -> f64 {
        ::libm::atan2(self, x)
    }
    fn exp_libm(self) -> f64 {
        ::libm::exp(self)
    }
    fn hypot_libm(self, other: f64) -> f64 {
        ::libm::hypot(self, other)
    }
    fn powf_libm(self, n: f64) -> f64 {
        ::libm::pow(self, n)
    }
}
