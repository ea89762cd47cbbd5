//! The vector instruction set the batch kernels run with: the widest this CPU has, or a
//! narrower one the caller asks for ([`limit_vector_isa`]). Every choice gives bit-identical
//! results (the kernels are one portable body built once per instruction set by
//! [`crate::isa_kernel`]); only the time differs.

use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction set a batch kernel is built for, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum VectorIsa {
    /// The target's baseline (SSE2 on x86-64): the fragments' scalar paths run instead of the
    /// batches wherever those were measured slower.
    Portable,
    /// AVX2 with BMI1, BMI2, LZCNT and FMA (4 lanes of 64 bits).
    Avx2,
    /// AVX-512 F, DQ, CD and VL (8 lanes of 64 bits, masks, 64-bit shifts and compares).
    Avx512,
}

impl VectorIsa {
    /// Every instruction set, narrowest first.
    pub const ALL: [Self; 3] = [Self::Portable, Self::Avx2, Self::Avx512];

    /// The name the CLI and `TEXSIM_VECTOR_ISA` use: `portable`, `avx2` or `avx512`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Portable => "portable",
            Self::Avx2 => "avx2",
            Self::Avx512 => "avx512",
        }
    }

    /// The instruction set named `name` ([`VectorIsa::name`]), if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|isa| isa.name() == name)
    }

    /// The widest instruction set this CPU has (std caches the detection).
    #[must_use]
    pub fn detected() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx512f") && has!("avx512dq") && has!("avx512cd") && has!("avx512vl") {
                return Self::Avx512;
            }
            if has!("avx2") && has!("bmi1") && has!("bmi2") && has!("lzcnt") && has!("fma") {
                return Self::Avx2;
            }
        }
        Self::Portable
    }

    const fn code(self) -> u8 {
        self as u8 + 1
    }
}

/// The instruction set in force, as [`VectorIsa::code`] (0: not chosen yet).
static IN_FORCE: AtomicU8 = AtomicU8::new(0);

/// The instruction set the batch kernels run with: [`VectorIsa::detected`], or the narrower
/// one [`limit_vector_isa`] chose.
#[inline(always)]
#[must_use]
pub fn vector_isa() -> VectorIsa {
    match IN_FORCE.load(Ordering::Relaxed) {
        1 => VectorIsa::Portable,
        2 => VectorIsa::Avx2,
        3 => VectorIsa::Avx512,
        _ => detect(),
    }
}

#[cold]
fn detect() -> VectorIsa {
    let isa = VectorIsa::detected();
    // A concurrent `limit_vector_isa` wins: it stores only after a detection.
    let _ = IN_FORCE.compare_exchange(0, isa.code(), Ordering::Relaxed, Ordering::Relaxed);
    vector_isa()
}

/// Whether the batch kernels run as vector lanes: [`vector_isa`] wider than
/// [`VectorIsa::Portable`] (where it is not, their callers take the scalar paths).
#[inline(always)]
#[must_use]
pub fn vector_batches() -> bool {
    vector_isa() > VectorIsa::Portable
}

/// Runs the batch kernels with `isa` from now on (for timing one instruction set against
/// another; results do not change). An error naming the widest this CPU has where `isa` is
/// wider.
pub fn limit_vector_isa(isa: VectorIsa) -> Result<(), VectorIsa> {
    let widest = VectorIsa::detected();
    if isa > widest {
        return Err(widest);
    }
    IN_FORCE.store(isa.code(), Ordering::Relaxed);
    Ok(())
}

/// Defines `fn $name` that runs `$body` built for the [`VectorIsa`] in force
/// ([`vector_isa`]): AVX-512 and AVX2 builds of the same body (so the compiler vectorizes its
/// branch-free loops at those widths), the portable build otherwise.
///
/// The generic parameters and the where clause go in brackets; `= body::<params>` names the
/// body and its generic arguments. `vector fn` defines a kernel without a portable build (its
/// callers take another path there): it returns whether it ran, `false` under
/// [`VectorIsa::Portable`] with nothing done, so that no unused portable build is compiled.
#[macro_export]
macro_rules! isa_kernel {
    (
        $(#[$m:meta])*
        $vis:vis fn $name:ident[$($g:tt)*]($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $(where[$($w:tt)*])? = $body:ident::<$($p:ident),*>;
    ) => {
        $(#[$m])*
        #[inline(always)]
        $vis fn $name<$($g)*>($($arg: $ty),*) $(-> $ret)? $(where $($w)*)? {
            $crate::isa_kernel!(
                @builds [$($g)*] ($($arg: $ty),*) [$(-> $ret)?] [$(where $($w)*)?]
                $body::<$($p),*> |r| r
            );
            $body::<$($p),*>($($arg),*)
        }
    };
    (
        $(#[$m:meta])*
        $vis:vis vector fn $name:ident[$($g:tt)*]($($arg:ident: $ty:ty),* $(,)?)
        $(where[$($w:tt)*])? = $body:ident::<$($p:ident),*>;
    ) => {
        $(#[$m])*
        #[inline(always)]
        #[must_use]
        $vis fn $name<$($g)*>($($arg: $ty),*) -> bool $(where $($w)*)? {
            $crate::isa_kernel!(
                @builds [$($g)*] ($($arg: $ty),*) [] [$(where $($w)*)?]
                $body::<$($p),*> |_r| true
            );
            let _ = ($($arg,)*);
            false
        }
    };
    // The AVX-512 and AVX2 builds of `$body`, and the call of the one in force, which returns
    // `$done` (of its result `$r`) from the function; nothing under `Portable`.
    (
        @builds [$($g:tt)*] ($($arg:ident: $ty:ty),*) [$($ret:tt)*] [$($wc:tt)*]
        $body:ident::<$($p:ident),*> |$r:ident| $done:expr
    ) => {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx512f,avx512dq,avx512cd,avx512vl")]
            fn avx512<$($g)*>($($arg: $ty),*) $($ret)* $($wc)* {
                $body::<$($p),*>($($arg),*)
            }
            #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,fma")]
            fn avx2<$($g)*>($($arg: $ty),*) $($ret)* $($wc)* {
                $body::<$($p),*>($($arg),*)
            }
            match $crate::isa::vector_isa() {
                $crate::isa::VectorIsa::Avx512 => {
                    // SAFETY: `vector_isa` is never wider than this CPU.
                    let $r = unsafe { avx512::<$($p),*>($($arg),*) };
                    return $done;
                }
                $crate::isa::VectorIsa::Avx2 => {
                    // SAFETY: as above.
                    let $r = unsafe { avx2::<$($p),*>($($arg),*) };
                    return $done;
                }
                $crate::isa::VectorIsa::Portable => {}
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_order_by_width() {
        for isa in VectorIsa::ALL {
            assert_eq!(VectorIsa::from_name(isa.name()), Some(isa));
        }
        assert_eq!(VectorIsa::from_name("sse9"), None);
        assert!(VectorIsa::Portable < VectorIsa::Avx2 && VectorIsa::Avx2 < VectorIsa::Avx512);
        assert!(vector_isa() <= VectorIsa::detected());
    }
}
