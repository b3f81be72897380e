//! The view's render: one at a time, on a thread of its own, shown at 1, 2,
//! 4, … samples per pixel and finally the number asked for, each step a
//! whole render with that count (the last is `glint render`'s image, bit
//! for bit). Asking with other flags stops it and starts another.

use crate::query::Flags;
use crate::Backend;
use glint_camera::Film;
use glint_integrator::{render_with, Aov, RenderControl, RenderSettings, SamplePattern};
use glint_scene::SceneDescription;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// The render in progress, if any.
#[derive(Default)]
pub(crate) struct Renders {
    current: Mutex<Option<Job>>,
}

struct Job {
    /// The flags, sorted: the same settings in another order are the same job.
    flags: Flags,
    progress: Arc<Progress>,
}

/// The lock's value, even if a panic held it before (every value here is
/// whole between statements).
fn locked<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
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
        let mut sorted = flags.clone();
        sorted.sort();
        let mut current = locked(&self.current);
        let progress = match current.as_ref() {
            Some(job) if job.flags == sorted => job.progress.clone(),
            _ => {
                if let Some(old) = current.take() {
                    old.progress.stop.store(true, Ordering::Relaxed);
                }
                let (scene, settings) = prepared(flags, backend)?;
                let progress = Arc::new(Progress::default());
                let shared = progress.clone();
                std::thread::spawn(move || {
                    let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        run(&scene, settings, &shared)
                    }));
                    if ran.is_err() {
                        *locked(&shared.error) = Some("the render failed".into());
                    }
                });
                *current = Some(Job {
                    flags: sorted,
                    progress: progress.clone(),
                });
                progress
            }
        };
        drop(current);
        if let Some(error) = locked(&progress.error).clone() {
            return Err(error);
        }
        let latest = locked(&progress.latest).clone();
        Ok(latest)
    }
}

impl Renders {
    /// The newest step of whatever render ran last.
    pub fn newest(&self) -> Option<Step> {
        let current = locked(&self.current);
        let latest = locked(&current.as_ref()?.progress.latest).clone();
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

/// The counts each step renders with: powers of two below `target` that
/// the pixel pattern takes (a grid only squares), then `target`; an AOV
/// (the same at every count) only `target`.
pub(crate) fn ladder(target: u32, aov: bool, pattern: SamplePattern) -> Vec<u32> {
    let below = (0..)
        .map(|k| 1u32 << k)
        .take_while(|&n| n < target && !aov)
        .filter(|&n| pattern.supports(n));
    below.chain(std::iter::once(target)).collect()
}

fn run(scene: &SceneDescription, mut settings: RenderSettings, progress: &Progress) {
    let target = settings.spp;
    for spp in ladder(target, settings.aov.is_some(), settings.pixel_pattern) {
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
                *locked(&progress.latest) = Some(step);
            }
            Err(e) => {
                *locked(&progress.error) = Some(e.to_string());
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ladder;
    use glint_integrator::SamplePattern::{Grid, Sobol};

    #[test]
    fn the_ladder_doubles_to_the_count_asked_for() {
        assert_eq!(ladder(16, false, Sobol), [1, 2, 4, 8, 16]);
        assert_eq!(ladder(12, false, Sobol), [1, 2, 4, 8, 12]);
        assert_eq!(ladder(1, false, Sobol), [1]);
        assert_eq!(ladder(64, true, Sobol), [64]);
        // A grid takes only squares.
        assert_eq!(ladder(64, false, Grid), [1, 4, 16, 64]);
    }
}
