//! `glint assemble`: the tiles or windows of one render, rendered apart
//! (`glint render --tile I/N` or `--crop`, on as many machines), put together
//! into the whole image, which is the single render's bit for bit: every
//! pixel depends only on the scene, the settings and its place in the image.
//! As pbrt-v4's `imgtool assemble`, it checks that the pieces cover the image
//! exactly once, and it checks that they are of one render (their
//! fingerprints), naming what is missing and what overlaps.

use crate::Failure;
use clap::Args;
use glam::UVec2;
use glint_camera::{Film, ImageFormat, PartialFilm, Tile};
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct AssembleArgs {
    /// The pieces: the .exr files written by `glint render --tile I/N` or
    /// `--crop` (with an .exr output) for the same scene and settings
    #[arg(required = true, value_name = "TILE")]
    tiles: Vec<PathBuf>,

    /// The whole image; the extension picks the format: .png (8-bit sRGB),
    /// .exr or .pfm (linear 32-bit float), the same bytes as `glint render`
    /// writes. Written atomically: a failed run leaves any existing file untouched
    #[arg(short, long, value_name = "OUT")]
    output: PathBuf,
}

/// The most tiles or regions one error line lists.
const LISTED: usize = 8;

pub(crate) fn assemble(args: &AssembleArgs) -> Result<(), Failure> {
    ImageFormat::from_path(&args.output).map_err(|e| Failure::Input(e.to_string()))?;
    crate::output::check_writable(&args.output)?;
    let inputs: Vec<&Path> = args.tiles.iter().map(PathBuf::as_path).collect();
    crate::output::check_outputs_apart(&[("-o", args.output.as_path())], &inputs)?;
    // One piece in memory at a time, beside the image: a tile's data window
    // spans nearly the whole image.
    // The first piece's render and image size, which the others must share.
    let mut first: Option<(Option<String>, UVec2)> = None;
    let mut film = Film::new(UVec2::ONE);
    // Per pixel, which piece holds it (its index plus one; 0 for none).
    let mut holder = Vec::new();
    let mut tiles = Vec::with_capacity(args.tiles.len());
    for (k, path) in args.tiles.iter().enumerate() {
        let piece = load_piece(path)?;
        match &first {
            None => {
                film = Film::new(piece.placement.image);
                holder = vec![0u32; film.pixels().len()];
                first = Some((piece.fingerprint.clone(), piece.placement.image));
            }
            Some(first) => check_one_render((&args.tiles[0], first), (path, &piece))?,
        }
        place(&mut film, &mut holder, k, &piece)
            .map_err(|(other, count, at)| overlap(&args.tiles, other, k, count, at))?;
        tiles.push(piece.tile);
    }
    let image = film.resolution();
    let missing = holder.iter().filter(|&&h| h == 0).count();
    if missing > 0 {
        return Err(Failure::Input(incomplete(&tiles, &holder, image, missing)));
    }
    film.save(&args.output)
        .map_err(|e| Failure::Other(e.to_string()))?;
    crate::output::say(&format!(
        "wrote {}: {}x{}, from {} pieces\n",
        args.output.display(),
        image.x,
        image.y,
        args.tiles.len()
    ));
    Ok(())
}

/// A piece as `glint render` finished it: named, and not an interrupted
/// render's partial pixels.
fn load_piece(path: &Path) -> Result<PartialFilm, Failure> {
    let piece = PartialFilm::load(path).map_err(|e| {
        Failure::Input(e.to_string().replace(
            "not the output of an interrupted render",
            "not a tile written by glint render --tile or --crop",
        ))
    })?;
    if piece.interrupted {
        return Err(Failure::Input(format!(
            "{}: an interrupted render's unfinished pixels, not a tile: finish it with the command that wrote it and --resume",
            path.display()
        )));
    }
    if piece.fingerprint.is_none() {
        return Err(Failure::Input(format!(
            "{}: does not name the render it is part of (it was not written by glint render --tile or --crop)",
            path.display()
        )));
    }
    Ok(piece)
}

/// Refuses a piece of another render than the first piece: another scene,
/// assets or settings (its fingerprint), or another image size.
fn check_one_render(
    (first_path, (fingerprint, image)): (&Path, &(Option<String>, UVec2)),
    (path, piece): (&Path, &PartialFilm),
) -> Result<(), Failure> {
    if piece.fingerprint != *fingerprint {
        return Err(Failure::Input(format!(
            "{}: a piece of another render than {} (the scene, its assets, the settings or Glint's version differ): assemble the pieces of one render",
            path.display(),
            first_path.display()
        )));
    }
    let (a, b) = (piece.placement.image, *image);
    if a != b {
        return Err(Failure::Input(format!(
            "{}: a piece of a {}x{} image, {} of a {}x{} one",
            path.display(),
            a.x,
            a.y,
            first_path.display(),
            b.x,
            b.y
        )));
    }
    Ok(())
}

/// Copies the pixels `piece` (number `k`) holds into `film`, marking them in
/// `holder`; or, if some are held already, the piece that holds them, how
/// many, and the first.
fn place(
    film: &mut Film,
    holder: &mut [u32],
    k: usize,
    piece: &PartialFilm,
) -> Result<(), (usize, usize, UVec2)> {
    let (width, size) = (film.resolution().x, piece.film.resolution());
    let origin = piece.placement.origin;
    let mut clash: Option<(usize, usize, UVec2)> = None;
    for (i, (&pixel, &held)) in piece.film.pixels().iter().zip(&piece.finished).enumerate() {
        if !held {
            continue;
        }
        let at = origin + UVec2::new(i as u32 % size.x, i as u32 / size.x);
        let index = (at.y * width + at.x) as usize;
        match holder[index] {
            0 => {
                holder[index] = k as u32 + 1;
                film.pixels_mut()[index] = pixel;
            }
            other => match &mut clash {
                Some((_, count, _)) => *count += 1,
                None => clash = Some((other as usize - 1, 1, at)),
            },
        }
    }
    clash.map_or(Ok(()), Err)
}

fn overlap(paths: &[PathBuf], other: usize, k: usize, count: usize, at: UVec2) -> Failure {
    Failure::Input(format!(
        "{} and {} both hold {count} pixel{} (the first at {},{}): each pixel must come from one piece; leave one of them out",
        paths[other].display(),
        paths[k].display(),
        if count == 1 { "" } else { "s" },
        at.x,
        at.y
    ))
}

/// What is missing, said so that it can be rendered: the tiles not given
/// where the pieces (`tiles`, as each says) are tiles of one count, else the
/// rows that lack pixels.
fn incomplete(tiles: &[Option<Tile>], holder: &[u32], image: UVec2, missing: usize) -> String {
    let counts: Vec<u32> = tiles.iter().filter_map(|t| t.map(|t| t.count)).collect();
    let all_tiles = counts.len() == tiles.len() && counts.iter().all(|&n| n == counts[0]);
    if all_tiles {
        let count = counts[0];
        let given: std::collections::HashSet<u32> =
            tiles.iter().filter_map(|t| t.map(|t| t.index)).collect();
        let absent: Vec<String> = (0..count)
            .filter(|i| !given.contains(i))
            .map(|index| Tile { index, count }.to_string())
            .collect();
        return format!(
            "{missing} of {} pixels are in no piece: missing tile{} {}; render {} with the same command and --tile, then assemble again",
            holder.len(),
            if absent.len() == 1 { "" } else { "s" },
            listed(&absent),
            if absent.len() == 1 { "it" } else { "them" }
        );
    }
    let width = image.x as usize;
    let empty_rows: Vec<u32> = (0..image.y)
        .filter(|&y| holder[y as usize * width..(y as usize + 1) * width].contains(&0))
        .collect();
    let spans: Vec<String> = row_spans(&empty_rows)
        .into_iter()
        .map(|(a, b)| match b - a {
            1 => format!("row {a}"),
            _ => format!("rows {a}-{}", b - 1),
        })
        .collect();
    format!(
        "{missing} of {} pixels are in no piece, in {}; render the windows that cover them (--crop) and assemble again",
        holder.len(),
        listed(&spans)
    )
}

/// Runs of consecutive rows, half-open.
fn row_spans(rows: &[u32]) -> Vec<(u32, u32)> {
    let mut spans: Vec<(u32, u32)> = Vec::new();
    for &y in rows {
        match spans.last_mut() {
            Some((_, end)) if *end == y => *end += 1,
            _ => spans.push((y, y + 1)),
        }
    }
    spans
}

/// Up to [`LISTED`] items, then how many more.
fn listed(items: &[String]) -> String {
    let shown = items[..items.len().min(LISTED)].join(", ");
    match items.len().saturating_sub(LISTED) {
        0 => shown,
        more => format!("{shown} and {more} more"),
    }
}
