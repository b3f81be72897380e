//! `glint view`'s server: a local web inspector. One job: show a browser on
//! this machine the images named on the command line, progressive renders of
//! one scene with its AOVs, `glint grade`'s and `glint diff`'s heat maps, and
//! every stage of one pixel (`glint explain`'s document), through a small
//! JSON API that the page and scripts share (docs/view.md).
//!
//! # Conventions
//! - **Safe by default.** It listens on 127.0.0.1 unless told otherwise, and
//!   answers only requests that carry the session's random token (`?token=`
//!   or the `X-Glint-Token` header), as Jupyter does. Nothing a request names
//!   is a path: images are numbered, the scene is the one given. Requests are
//!   `GET`s without bodies; anything else, a URL over 8 KiB or a body is
//!   refused with a 4xx and a one-line message. No input makes it panic.
//! - **Images** cross as little-endian `f32` linear RGB, rows from the top
//!   (`/api/image`, `/api/render`), with their size in `X-Width` and
//!   `X-Height`; or as PNG (8-bit sRGB, as `glint render` writes it) or EXR
//!   with `as=png` or `as=exr`.
//! - **Settings** are `glint render`'s and `glint explain`'s flags by name
//!   (`spp=4&light-samples=16&sampler=random`). The command line turns them
//!   into a scene and an explain document ([`Backend`]), so a flag means here
//!   exactly what it means there, and `/api/explain` answers the bytes
//!   `glint explain SCENE --json` prints with the same flags.
//! - **Renders** run on their own thread (Glint's thread pool inside it),
//!   never on a request's: the page asks for the newest image and gets what
//!   there is. A render at N samples per pixel is shown at 1, 2, 4, … and
//!   finally N, each a whole render, the last `glint render`'s bit for bit.

mod api;
mod http;
mod progressive;
mod query;

use glint_scene::SceneDescription;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

pub use query::Flags;

/// What the command line gives the server.
pub struct ViewConfig {
    /// Where to listen (127.0.0.1 unless asked otherwise; port 0 for any).
    pub address: SocketAddr,
    /// The scene file, if any (renders, explain and grading need one).
    pub scene: Option<PathBuf>,
    /// The images to show, each read once at start.
    pub images: Vec<PathBuf>,
    /// A student's explain document: `/api/against` compares with it.
    pub against: bool,
}

/// The command line's part: scenes and explain documents made from flags
/// exactly as its commands make them.
pub trait Backend: Send + Sync {
    /// The scene with `glint render`'s `flags` applied, or the message
    /// `glint render` would print for them.
    fn scene(&self, flags: &Flags) -> Result<Arc<SceneDescription>, String>;
    /// What `glint explain SCENE --json` prints with `flags` (`--against`
    /// the student's document as well where `against`), or its message.
    fn explain(&self, flags: &Flags, against: bool) -> Result<String, String>;
}

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("{path}: {message}")]
    Image { path: PathBuf, message: String },
    #[error("cannot listen on {address}: {message}")]
    Listen {
        address: SocketAddr,
        message: String,
    },
    #[error("cannot make the session's token: {0}")]
    Token(String),
}

/// Serves until `stop` is set: reads the images, binds the address, calls
/// `ready` with the page's URL (token included), then answers requests.
pub fn serve(
    config: ViewConfig,
    backend: Arc<dyn Backend>,
    stop: &AtomicBool,
    ready: &mut dyn FnMut(&str),
) -> Result<(), ViewError> {
    let images = api::Images::read(&config.images)?;
    let token = http::token().map_err(ViewError::Token)?;
    let state = api::State::new(images, config.scene, config.against, backend);
    http::run(config.address, &token, stop, ready, &|request| {
        state.answer(request)
    })
}
