//! `glint grade --stages`: test vectors for each stage of a student's ray
//! tracer, and the check of their answers. (Being written.)

use crate::Failure;
use std::path::PathBuf;

/// The flags of `glint grade --stages`.
pub(crate) struct StageArgs {
    pub scene: PathBuf,
    pub write: Option<PathBuf>,
    pub answers: Option<PathBuf>,
    pub cases: Option<u32>,
    pub format_json: bool,
}

pub(crate) fn run(args: &StageArgs) -> Result<(), Failure> {
    let _ = (&args.scene, &args.write, &args.answers, args.cases, args.format_json);
    Err(Failure::Input("glint grade --stages is not written yet".into()))
}
