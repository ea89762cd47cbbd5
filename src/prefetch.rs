//! A cache hint for the frame's scattered per-triangle reads: the raster walks a band's
//! triangles by index and the shading pass reads each span's triangle, so the next one's data
//! can be on its way while the current one is worked on.

/// Asks the core to bring `v[i]` into its caches ahead of a read: the lines at its first byte
/// and every 64 bytes on (an item that does not start on a line may leave the line of its
/// last bytes out; covering it too measured no faster on W2 or the million-triangle grid). A
/// hint: it changes no result, and does nothing off x86-64 or when `i` is out of bounds.
#[inline(always)]
pub(crate) fn prefetch<T>(v: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(x) = v.get(i) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = (x as *const T).cast::<i8>();
        for line in (0..std::mem::size_of::<T>()).step_by(64) {
            // SAFETY: a prefetch only hints the caches and never faults; SSE, which has it,
            // is part of every x86-64 target; the address lies inside `v[i]`.
            unsafe { _mm_prefetch(p.wrapping_add(line), _MM_HINT_T0) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, i);
}

#[cfg(test)]
mod tests {
    use super::prefetch;

    #[test]
    fn a_prefetch_anywhere_changes_nothing() {
        let v: Vec<[u64; 40]> = (0..3).map(|k| [k; 40]).collect();
        for i in [0, 2, 3, usize::MAX] {
            prefetch(&v, i);
        }
        prefetch::<u8>(&[], 0);
        assert_eq!(v, (0..3).map(|k| [k; 40]).collect::<Vec<_>>());
    }
}
