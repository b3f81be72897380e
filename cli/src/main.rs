//! The `glint` program: [`glint_cli::run`] on this process's command line.

use std::process::ExitCode;

/// Makes glibc's malloc give every block of 128 KiB or more its own mapping,
/// returned to the system when freed. By default glibc raises that threshold
/// to the size of each such block freed, up to 32 MiB: a BVH build's
/// thousands of per-subtree node lists then stay in the threads' heaps when
/// freed, and a 4M-triangle mesh's peak was 618 MiB where it is 498 with
/// this (Intel Xeon; `docs/speed.md`).
fn return_large_blocks_at_once() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` takes two integers and touches no memory of ours;
    // glibc documents it as safe to call before other threads exist
    // (MT-Unsafe init), and it runs first thing in `main`, before this
    // process starts any thread.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

fn main() -> ExitCode {
    return_large_blocks_at_once();
    ExitCode::from(glint_cli::run(None, std::env::args_os().collect()))
}
