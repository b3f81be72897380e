//! Ctrl-C (SIGINT) and SIGTERM during a render. The first asks the render to
//! stop, so that the pixels finished so far are written; a second of either
//! exits at once with the status of that signal (128 + its number), but never
//! in the middle of writing a file: an output being written is completed and
//! renamed into place first (milliseconds), so no partial or hidden temporary
//! file is ever left behind.

use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// The interrupt signals received since [`Interrupts::install`].
pub(crate) struct Interrupts {
    /// Set by the first signal: what the render loop watches.
    stop: Arc<AtomicBool>,
    terminated: Arc<AtomicBool>,
    /// Held while an output file is written; a second signal waits for it.
    writing: Arc<Mutex<()>>,
}

impl Interrupts {
    /// Replaces the default action of SIGINT and SIGTERM (ending the process at
    /// once) by a thread that handles them as the module says.
    pub(crate) fn install() -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let terminated = Arc::new(AtomicBool::new(false));
        let writing = Arc::new(Mutex::new(()));
        let mut signals = Signals::new([SIGINT, SIGTERM])?;
        let (s, t, w) = (
            Arc::clone(&stop),
            Arc::clone(&terminated),
            Arc::clone(&writing),
        );
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for signal in signals.forever() {
                    if signal == SIGTERM {
                        t.store(true, Ordering::SeqCst);
                    }
                    if s.swap(true, Ordering::SeqCst) {
                        let _finish_the_write = w.lock();
                        std::process::exit(128 + signal);
                    }
                }
            })?;
        Ok(Self {
            stop,
            terminated,
            writing,
        })
    }

    /// The flag the render stops on.
    pub(crate) fn stop(&self) -> &AtomicBool {
        &self.stop
    }

    /// Hold this while writing a file: a second signal exits only after.
    pub(crate) fn writing(&self) -> MutexGuard<'_, ()> {
        self.writing.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The exit status for the signal received, if any: 143 for SIGTERM, 130
    /// for Ctrl-C, as a shell reports a process these signals ended.
    pub(crate) fn exit_status(&self) -> Option<u8> {
        if self.terminated.load(Ordering::SeqCst) {
            Some(128 + SIGTERM as u8)
        } else if self.stop.load(Ordering::SeqCst) {
            Some(128 + SIGINT as u8)
        } else {
            None
        }
    }
}
