//! The memory budget against what a run really takes: the per-triangle estimate
//! (`budget::BYTES_PER_TRIANGLE`, `BYTES_PER_VERTEX`) bounds the peak resident memory a fully
//! visible mesh adds.

use super::cli_common::tmp;
use std::path::Path;
use std::process::{Command, Stdio};
use texsim::budget::{BYTES_PER_TRIANGLE, BYTES_PER_VERTEX};

/// Writes an `n` x `n` quad grid facing the camera (2 n^2 triangles, (n + 1)^2 vertices) with
/// texture coordinates as `grid.obj` in `dir`.
fn grid_obj(dir: &Path, n: u32) -> std::path::PathBuf {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            s += &format!("v {x:.6} {y:.6} 0\nvt {x:.6} {y:.6}\n");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, e) = (a + 1, a + n + 2, a + n + 1);
            s += &format!("f {a}/{a} {b}/{b} {c}/{c} {e}/{e}\n");
        }
    }
    let p = dir.join(format!("grid{n}.obj"));
    std::fs::write(&p, s).expect("write grid");
    p
}

/// Peak resident memory (bytes) of `texsim render OBJ` at 256x256, and its exit status.
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes)] // `wait4` below reaps the child (and reads its usage).
fn peak_rss(obj: &Path, out: &Path) -> (u64, i32) {
    let child = Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(["--threads", "2", "render"])
        .arg(obj)
        .args([
            "--width",
            "256",
            "--height",
            "256",
            "--no-reference",
            "--no-cycles",
        ])
        .args(["--no-flip", "--out"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("run texsim");
    let mut status = 0;
    // SAFETY: an all-zero `rusage` is valid; `wait4` reaps the child it was given and fills
    // both out-parameters.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t, "wait4");
    // `ru_maxrss` is in KiB on Linux.
    (u64::try_from(usage.ru_maxrss).unwrap_or(0) * 1024, status)
}

/// A fully visible 180,000-triangle grid adds less peak resident memory over a 3,200-triangle
/// one than the budget estimates for the difference, and not less than half of it (the
/// estimate is an upper bound, not a multiple of the need).
#[cfg(target_os = "linux")]
#[test]
fn triangle_budget_bounds_the_peak_memory_of_a_visible_mesh() {
    let d = tmp("budget-grid");
    let (small, big) = (40u32, 300u32);
    let (rss_small, st_small) = peak_rss(&grid_obj(&d, small), &d.join("out-small"));
    let (rss_big, st_big) = peak_rss(&grid_obj(&d, big), &d.join("out-big"));
    assert_eq!((st_small, st_big), (0, 0), "both renders succeed");
    let estimate = |n: u32| {
        let (n, v) = (u64::from(n), u64::from(n + 1).pow(2));
        2 * n * n * BYTES_PER_TRIANGLE + v * BYTES_PER_VERTEX
    };
    let need = estimate(big) - estimate(small);
    let took = rss_big.saturating_sub(rss_small);
    assert!(
        took <= need && 2 * took >= need,
        "peak RSS grew by {took} B for {} more triangles; the budget estimates {need} B",
        2 * (big * big - small * small)
    );
}
