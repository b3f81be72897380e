//! `glint view`: the local web inspector ([`glint_view`]), with this
//! program's flags behind its API: a request's settings are parsed by the
//! same definitions as `glint render`'s and `glint explain`'s flags, so they
//! mean the same and `/api/explain` answers `glint explain --json`'s bytes.

use crate::explain::{explained, ExplainArgs};
use crate::render::SceneArgs;
use crate::Failure;
use clap::{Args, Parser};
use glint_scene::{Overrides, SceneDescription};
use glint_view::{Backend, Flags, ViewConfig};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

#[derive(Args)]
pub(crate) struct ViewArgs {
    /// A scene file (.toml) to render, explain and grade against, then the
    /// images to show (any format Glint reads)
    #[arg(value_name = "SCENE.toml|IMAGE", required = true)]
    inputs: Vec<PathBuf>,

    /// The port to listen on (any free one if not given)
    #[arg(long, value_name = "N", default_value_t = 0)]
    port: u16,

    /// The address to listen on; another than 127.0.0.1 lets other machines
    /// in (each still needs the printed URL's token)
    #[arg(long, value_name = "ADDRESS", default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    host: IpAddr,

    /// Print the URL but open no browser
    #[arg(long)]
    no_open: bool,

    /// A student's explain document: each clicked pixel's stages are
    /// compared with it, and the first where it parts is marked
    #[arg(long, value_name = "STUDENT.json")]
    against: Option<PathBuf>,

    /// Open framing this block of the first image (half-open, rows from the
    /// top), its centre pixel explained: what `glint grade --report` gives
    /// for each of a failed submission's rejected regions
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = glint_metrics::Region::parse)]
    region: Option<glint_metrics::Region>,
}

pub(crate) fn view(args: &ViewArgs) -> Result<(), Failure> {
    let (scene, images) = match args.inputs.split_first() {
        Some((first, rest)) if first.extension().is_some_and(|e| e == "toml") => {
            (Some(first.clone()), rest.to_vec())
        }
        _ => (None, args.inputs.clone()),
    };
    if args.region.is_some() && images.is_empty() {
        return Err(Failure::Input(
            "--region frames the first image: give an image".into(),
        ));
    }
    if scene.is_none() && args.against.is_some() {
        return Err(Failure::Input("--against needs a scene file first".into()));
    }
    let backend = Arc::new(CliBackend {
        scene: scene.clone(),
        against: args.against.clone(),
        loaded: Mutex::default(),
    });
    if scene.is_some() {
        backend.scene(&Flags::new()).map_err(Failure::Input)?;
    }
    if let Some(student) = &args.against {
        glint_scene::read_text(student, glint_scene::MAX_DOCUMENT_BYTES, "a document")
            .map_err(|e| Failure::Input(format!("{}: {e}", student.display())))?;
    }
    if !args.host.is_loopback() {
        crate::output::tell(&format!(
            "glint view: warning: listening on {}: other machines can connect (each needs the URL's token)",
            args.host
        ));
    }
    let config = ViewConfig {
        address: SocketAddr::new(args.host, args.port),
        scene,
        images,
        against: args.against.is_some(),
    };
    let interrupts = crate::interrupt::Interrupts::install()
        .map_err(|e| Failure::Other(format!("cannot watch for Ctrl-C: {e}")))?;
    let open = !args.no_open;
    let framed = args
        .region
        .map(|r| format!("#region={r}"))
        .unwrap_or_default();
    let mut ready = |url: &str| {
        let url = format!("{url}{framed}");
        let url = url.as_str();
        crate::output::say(&format!("{url}\n"));
        if open {
            open_browser(url);
        }
    };
    glint_view::serve(config, backend, interrupts.stop(), &mut ready).map_err(|e| match e {
        glint_view::ViewError::Image { .. } => Failure::Input(e.to_string()),
        _ => Failure::Other(e.to_string()),
    })?;
    crate::output::tell("glint view: stopped");
    Ok(())
}

/// Opens `url` in the desktop's browser, if there is one to ask.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    let started = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if started.is_err() {
        crate::output::tell(&format!(
            "glint view: open {url} in a browser ({opener} is not here)"
        ));
    }
}

/// The flags a request may not give: they name files, or change what is
/// printed or which scene is explained, which the server decides.
const RESERVED: [&str; 3] = ["against", "json", "mistake"];
/// Loaded scenes kept, by the settings they were loaded with.
const SCENES_KEPT: usize = 4;

struct CliBackend {
    scene: Option<PathBuf>,
    against: Option<PathBuf>,
    loaded: Mutex<Vec<(Overrides, Arc<SceneDescription>)>>,
}

/// `glint render`'s scene flags alone.
#[derive(Parser)]
#[command(name = "glint view", no_binary_name = true)]
struct SceneFlags {
    #[command(flatten)]
    scene: SceneArgs,
}

/// `glint explain`'s flags.
#[derive(Parser)]
#[command(name = "glint view", no_binary_name = true)]
struct ExplainFlags {
    #[command(flatten)]
    explain: ExplainArgs,
}

impl CliBackend {
    /// `flags` as `--NAME=VALUE` (`--NAME` for a switch given no value), so
    /// that no value is ever read as another flag; then `--` and `path`, so
    /// that no file name is either.
    fn argv(path: &Path, flags: &Flags) -> Result<Vec<std::ffi::OsString>, String> {
        let mut argv: Vec<std::ffi::OsString> = Vec::new();
        for (name, value) in flags {
            if RESERVED.contains(&name.as_str()) {
                return Err(format!("--{name} is not given through the view"));
            }
            argv.push(match value.as_str() {
                "" => format!("--{name}").into(),
                value => format!("--{name}={value}").into(),
            });
        }
        argv.push("--".into());
        argv.push(path.into());
        Ok(argv)
    }

    fn loaded(&self, args: &SceneArgs) -> Result<Arc<SceneDescription>, String> {
        let overrides = args.overrides();
        let mut loaded = (self.loaded.lock()).unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((_, scene)) = loaded.iter().find(|(o, _)| *o == overrides) {
            return Ok(scene.clone());
        }
        let scene = Arc::new(args.load().map_err(message)?);
        if loaded.len() >= SCENES_KEPT {
            loaded.remove(0);
        }
        loaded.push((overrides, scene.clone()));
        Ok(scene)
    }

    fn path(&self) -> Result<&Path, String> {
        self.scene
            .as_deref()
            .ok_or_else(|| "glint view was given no scene".into())
    }
}

impl Backend for CliBackend {
    fn scene(&self, flags: &Flags) -> Result<Arc<SceneDescription>, String> {
        let argv = Self::argv(self.path()?, flags)?;
        let parsed = SceneFlags::try_parse_from(argv).map_err(clap_message)?;
        self.loaded(&parsed.scene)
    }

    fn explain(&self, flags: &Flags, against: bool) -> Result<String, String> {
        let mut argv = Self::argv(self.path()?, flags)?;
        argv.insert(0, "--json".into());
        if against {
            let student = self
                .against
                .as_ref()
                .ok_or("no student's document was given")?;
            let mut flag = std::ffi::OsString::from("--against=");
            flag.push(student);
            argv.insert(0, flag);
        }
        let parsed = ExplainFlags::try_parse_from(argv).map_err(clap_message)?;
        let scene = self.loaded(parsed.explain.scene())?;
        Ok(explained(&parsed.explain, &scene, None)
            .map_err(message)?
            .text)
    }
}

fn message(failure: Failure) -> String {
    match failure {
        Failure::Input(m) | Failure::Other(m) | Failure::Internal(m) => m,
        Failure::Verdict(m) => m.unwrap_or_default(),
        Failure::Interrupted { message, .. } => message,
        Failure::Panicked => "an internal error".into(),
    }
}

/// clap's first line, without its "error: ".
fn clap_message(e: clap::Error) -> String {
    let text = e.render().to_string();
    let first = text.lines().next().unwrap_or_default();
    first.strip_prefix("error: ").unwrap_or(first).to_owned()
}
