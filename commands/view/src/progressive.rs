//! The view's render: one at a time, on a thread of its own, shown at 1, 2,
//! 4, … samples per pixel and finally the number asked for, each step a
//! whole render with that count (the last is `glint render`'s image, bit
//! for bit). Asking with other flags stops it and starts another.

use crate::query::Flags;
use crate::Backend;
use glint_camera::Film;
use glint_integrator::{render_with, Aov, RenderControl, RenderSettings};
use glint_scene::SceneDescription;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// The render in progress, if any.
#[derive(Default)]
pub(crate) struct Renders {
    current: Mutex<Option<Job>>,
}

struct Job {
    flags: Flags,
    progress: Arc<Progress>,
}

/// What a job has made so far, shared with its thread.
#[derive(Default)]
struct Progress {
    latest: Mutex<Option<Step>>,
    error: Mutex<Option<String>>,
    stop: AtomicBool,
}

/// The newest whole render of a job.
#[derive(Clone)]
pub(crate) struct Step {
    pub film: Arc<Film>,
    pub spp: u32,
    pub target: u32,
}

impl Renders {
    /// The newest step of the render with `flags` (`glint render`'s, and
    /// `aov`), starting it (and stopping any other) when it is not the one
    /// running: `None` until its first step is done; an error for flags the
    /// command line refuses, or a render that failed.
    pub fn latest(&self, flags: &Flags, backend: &dyn Backend) -> Result<Option<Step>, String> {
        let mut current = self
            .current
            .lock()
            .map_err(|_| "a render failed".to_owned())?;
        if current.as_ref().is_none_or(|job| job.flags != *flags) {
            if let Some(old) = current.take() {
                old.progress.stop.store(true, Ordering::Relaxed);
            }
            let (scene, settings) = prepared(flags, backend)?;
            let progress = Arc::new(Progress::default());
            let shared = progress.clone();
            std::thread::spawn(move || run(&scene, settings, &shared));
            *current = Some(Job {
                flags: flags.clone(),
                progress,
            });
        }
        let progress = current.as_ref().expect("started above").progress.clone();
        drop(current);
        if let Some(error) = progress
            .error
            .lock()
            .map_err(|_| "a render failed")?
            .clone()
        {
            return Err(error);
        }
        let latest = progress
            .latest
            .lock()
            .map_err(|_| "a render failed")?
            .clone();
        Ok(latest)
    }
}

impl Renders {
    /// The newest step of whatever render ran last.
    pub fn newest(&self) -> Option<Step> {
        let current = self.current.lock().ok()?;
        let latest = current.as_ref()?.progress.latest.lock().ok()?.clone();
        latest
    }
}

/// The scene and settings `flags` ask for: `aov` taken out and set, the
/// rest the command line's.
fn prepared(
    flags: &Flags,
    backend: &dyn Backend,
) -> Result<(Arc<SceneDescription>, RenderSettings), String> {
    let aov = crate::query::get(flags, "aov")
        .map(|name| {
            Aov::from_name(name).ok_or_else(|| {
                format!(
                    "aov: unknown buffer \"{}\"; expected one of {}",
                    crate::query::shorten(name),
                    Aov::NAMES.join(", ")
                )
            })
        })
        .transpose()?;
    let rest: Flags = flags.iter().filter(|(n, _)| n != "aov").cloned().collect();
    let scene = backend.scene(&rest)?;
    let mut settings = scene.settings.clone();
    settings.aov = aov;
    Ok((scene, settings))
}

/// The counts each step renders with: powers of two below `target`, then
/// `target`; an AOV (the same at every count) only `target`.
pub(crate) fn ladder(target: u32, aov: bool) -> Vec<u32> {
    let below = (0..).map(|k| 1u32 << k).take_while(|&n| n < target && !aov);
    below.chain(std::iter::once(target)).collect()
}

fn run(scene: &SceneDescription, mut settings: RenderSettings, progress: &Progress) {
    let target = settings.spp;
    for spp in ladder(target, settings.aov.is_some()) {
        settings.spp = spp;
        let control = RenderControl {
            stop: Some(&progress.stop),
            ..RenderControl::default()
        };
        match render_with(&scene.scene, &settings, &|_, _| {}, control) {
            _ if progress.stop.load(Ordering::Relaxed) => return,
            Ok(output) => {
                let step = Step {
                    film: Arc::new(output.film),
                    spp,
                    target,
                };
                if let Ok(mut latest) = progress.latest.lock() {
                    *latest = Some(step);
                }
            }
            Err(e) => {
                if let Ok(mut error) = progress.error.lock() {
                    *error = Some(e.to_string());
                }
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ladder;

    #[test]
    fn the_ladder_doubles_to_the_count_asked_for() {
        assert_eq!(ladder(16, false), [1, 2, 4, 8, 16]);
        assert_eq!(ladder(12, false), [1, 2, 4, 8, 12]);
        assert_eq!(ladder(1, false), [1]);
        assert_eq!(ladder(64, true), [64]);
    }
}
