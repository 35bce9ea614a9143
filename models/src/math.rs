//! The transcendental functions of the models, from one pure-Rust implementation on every
//! platform: the `libm` crate (a port of musl's libm).
//!
//! `f64::sin` and its kin call the platform's C library: glibc on linux64, MinGW-w64's and
//! msvcrt's on win64. They differ in the last bits, and a model that integrates or feeds back
//! carries such a difference on (the linux64 and win64 builds of the Current FMU differed by
//! 3e-5 of a variable that should be 0, `speed · cos(π/2)`). Every other operation of the
//! models is IEEE-754 arithmetic (or `sqrt`, correctly rounded everywhere), so with these the
//! FMUs give the same bits on linux64 and win64 (tests/python/test_win64.py checks it; the cost
//! is in docs/windows.md).
//!
//! The names are those of the `f64` methods they replace (`ln`, `powf`, `sin_cos`), so a model
//! reads `sin(psi)` for `psi.sin()`. `clippy.toml` forbids the `f64` methods in `models/` and
//! the FMU crates.
//!
//! `cargo xtask bench` builds the RRS FMUs with `--cfg shipsim_platform_libm`, where these call
//! the platform's library instead, to measure what the one libm costs (docs/bench.md).
#![allow(clippy::disallowed_methods)]

/// The platform's C library instead of `libm` (a bench variant only).
const PLATFORM: bool = cfg!(shipsim_platform_libm);

/// sin x
#[inline]
pub fn sin(x: f64) -> f64 {
    if PLATFORM {
        x.sin()
    } else {
        libm::sin(x)
    }
}

/// cos x
#[inline]
pub fn cos(x: f64) -> f64 {
    if PLATFORM {
        x.cos()
    } else {
        libm::cos(x)
    }
}

/// (sin x, cos x)
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if PLATFORM {
        x.sin_cos()
    } else {
        libm::sincos(x)
    }
}

/// arcsin x
#[inline]
pub fn asin(x: f64) -> f64 {
    if PLATFORM {
        x.asin()
    } else {
        libm::asin(x)
    }
}

/// arctan x
#[inline]
pub fn atan(x: f64) -> f64 {
    if PLATFORM {
        x.atan()
    } else {
        libm::atan(x)
    }
}

/// The four-quadrant arctangent of y/x (`atan2(y, x)`).
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    if PLATFORM {
        y.atan2(x)
    } else {
        libm::atan2(y, x)
    }
}

/// eˣ
#[inline]
pub fn exp(x: f64) -> f64 {
    if PLATFORM {
        x.exp()
    } else {
        libm::exp(x)
    }
}

/// eˣ − 1, accurate near 0
#[inline]
pub fn exp_m1(x: f64) -> f64 {
    if PLATFORM {
        x.exp_m1()
    } else {
        libm::expm1(x)
    }
}

/// The natural logarithm.
#[inline]
pub fn ln(x: f64) -> f64 {
    if PLATFORM {
        x.ln()
    } else {
        libm::log(x)
    }
}

/// The base-10 logarithm.
#[inline]
pub fn log10(x: f64) -> f64 {
    if PLATFORM {
        x.log10()
    } else {
        libm::log10(x)
    }
}

/// xʸ (`powf(x, y)`)
#[inline]
pub fn powf(x: f64, y: f64) -> f64 {
    if PLATFORM {
        x.powf(y)
    } else {
        libm::pow(x, y)
    }
}

/// √(x² + y²) without overflow
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    if PLATFORM {
        x.hypot(y)
    } else {
        libm::hypot(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spot values against the platform's library: the two agree to a few units in the last
    /// place (they are not required to agree to the bit, which is the point of this module).
    #[test]
    #[allow(clippy::disallowed_methods)]
    fn agrees_with_the_platform_library() {
        let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs().max(1e-300);
        for &x in &[0.1, 0.5, 1.0, 2.0, 3.0, 10.0, -7.5, 1e3] {
            assert!(close(sin(x), x.sin()), "sin {x}");
            assert!(close(cos(x), x.cos()), "cos {x}");
            assert_eq!(sin_cos(x), (sin(x), cos(x)));
            assert!(close(atan2(x, 0.7), x.atan2(0.7)), "atan2 {x}");
            assert!(close(atan(x), x.atan()), "atan {x}");
            assert!(close(exp(x / 10.0), (x / 10.0).exp()), "exp {x}");
            assert!(close(exp_m1(x / 1e3), (x / 1e3).exp_m1()), "exp_m1 {x}");
            assert!(close(powf(x.abs(), 1.3), x.abs().powf(1.3)), "powf {x}");
            assert!(close(hypot(x, 3.0), x.hypot(3.0)), "hypot {x}");
            if x > 0.0 {
                assert!(close(ln(x), x.ln()), "ln {x}");
                assert!(close(log10(x), x.log10()), "log10 {x}");
            }
        }
        assert!(close(asin(0.5), 0.5f64.asin()));
    }
}
