//! `texsim`: see `texsim --help`. Without arguments it renders the built-in demo into ./out.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    restore_sigpipe();
    keep_freed_memory();
    let cli = match texsim::cli::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match texsim::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("texsim: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Rust ignores SIGPIPE, so printing into a closed pipe (`texsim hw show | head -1`) would panic
/// in `println!`; with the default disposition the process ends quietly, as Unix tools do.
#[cfg(unix)]
fn restore_sigpipe() {
    // SAFETY: called first in `main`, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn restore_sigpipe() {}

/// Keeps the memory a frame frees for the next one. Every render allocates its per-triangle and
/// per-pixel buffers afresh (W2's 60,619 screen triangles and their attributes alone take
/// about 18 MB). By default glibc serves such a buffer from its own mapping or trims it
/// off a heap when it is freed (thresholds of 128 KiB that glibc raises as it goes), so a
/// later frame may get new pages that the kernel zeroes and maps one by one: at two threads
/// about one W2 frame in two spent 2-4 ms more in setup that way. Buffers below 32 MiB
/// (glibc's largest threshold) now come from the heaps and go back to them, and up to 1 GiB of
/// free memory stays mapped; the process's peak memory is unchanged. The CLI sets it; a library
/// user keeps their own allocator's settings.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_memory() {
    // SAFETY: called in `main` before any other thread exists; `mallopt` only sets the
    // allocator's parameters (a value it refuses leaves the default).
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_memory() {}
