//! A render from Python: on Glint's threads, the GIL released, the calling
//! thread watching for signals and reporting progress.

use glint_camera::Film;
use glint_integrator::{Crop, RenderControl, RenderSettings, Scene};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How long the calling thread waits between looks at signals and progress.
const SLICE: Duration = Duration::from_millis(50);

/// The film of `scene` under `settings` (the window `crop` of it), rendered
/// on a thread of its own while this one waits without the GIL; a signal
/// handler's exception (Ctrl-C's `KeyboardInterrupt`) stops the render at
/// the next pixel and is raised; `progress(done, total)` is called here as
/// tiles finish.
pub(crate) fn render(
    py: Python<'_>,
    scene: &Scene,
    settings: &RenderSettings,
    crop: Option<Crop>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Film> {
    let stop = AtomicBool::new(false);
    let (done, total) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let on_tile = |d: usize, t: usize| {
        done.store(d, Ordering::Relaxed);
        total.store(t, Ordering::Relaxed);
    };
    let finished = (Mutex::new(None), Condvar::new());
    std::thread::scope(|s| {
        s.spawn(|| {
            let control = RenderControl {
                stop: Some(&stop),
                resume: None,
                crop,
            };
            let rendered = glint_integrator::render_with(scene, settings, &on_tile, control);
            *finished.0.lock().expect("no panic holds it") = Some(rendered);
            finished.1.notify_one();
        });
        let mut reported = usize::MAX;
        loop {
            let waited = py.detach(|| {
                let slot = finished.0.lock().expect("no panic holds it");
                let (mut slot, _) = (finished.1)
                    .wait_timeout_while(slot, SLICE, |r| r.is_none())
                    .expect("no panic holds it");
                slot.take()
            });
            let d = done.load(Ordering::Relaxed);
            if let (Some(progress), true) = (progress, d != reported) {
                reported = d;
                if let Err(e) = progress.call1((d, total.load(Ordering::Relaxed))) {
                    stop.store(true, Ordering::Relaxed);
                    return Err(e);
                }
            }
            if let Some(rendered) = waited {
                let rendered =
                    rendered.map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
                return Ok(rendered.film);
            }
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                return Err(e);
            }
        }
    })
}
