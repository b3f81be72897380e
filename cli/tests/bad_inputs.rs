//! The bad-input corpus (`tests/bad-inputs/`, its README says how a case is
//! laid out): every case, run as a user would (by default `glint render
//! scene.toml -o out.png`, or the case's own `command`), gives one clear error
//! line of at most [`LINE_BYTES`] bytes containing its `expected` text, exit
//! status 2, no panic, within a bounded time and address space, and leaves
//! everything it could reach as it was: the folder it ran in (every file byte
//! for byte, FIFOs and links by kind and target), its home and its temporary
//! folder (nothing written there), no output file, no temporary file behind.

#![cfg(unix)]

mod common;

use common::{input_error_problem, stderr};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

/// Longest a case may take: a bad input is refused, not rendered.
const TIME_LIMIT: Duration = Duration::from_secs(20);

/// The address space a case runs in (`ulimit -v`, KiB): an input that would
/// exhaust memory must be refused before allocating, not abort.
const ADDRESS_SPACE_KIB: u64 = 4 << 20;

/// The longest error line, in bytes (its newline not counted): echoed values
/// are cut, so a name of 100 000 characters never makes a line of 100 000.
const LINE_BYTES: usize = 1200;

/// What a user had in the folder before the run: `out.png`, the default
/// output of every case, must be there after it unchanged.
const PRECIOUS: &[u8] = b"an image the user wants to keep";

/// The files of a case folder that describe the case: not copied into the
/// folder it runs in.
const CASE_FILES: [&str; 4] = ["expected", "args", "command", "setup"];

/// Every command of `glint`: the corpus has a case for each.
const COMMANDS: [&str; 7] = [
    "render", "diff", "bench", "stress", "export", "explain", "grade",
];

/// The classes of bad input issue 30 names, as the case folders spell them
/// (`COMMAND-CLASS-WHAT`): the corpus has a case of each.
const CLASSES: [&str; 4] = ["crash", "silent", "message", "early"];

/// Files larger than this (made by `setup`'s `sized`) are compared by length
/// and modification time, not read: reading gigabytes twice would take seconds.
const READ_LIMIT: u64 = 64 << 20;

fn corpus() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/bad-inputs")
}

/// Copies the case folder `from` into `to`, leaving out the files that
/// describe the case.
fn copy_case(from: &Path, to: &Path) {
    fn copy_dir(from: &Path, to: &Path, top: bool) {
        std::fs::create_dir_all(to).unwrap();
        for entry in std::fs::read_dir(from).unwrap() {
            let entry = entry.unwrap();
            let name = entry.file_name();
            if top && CASE_FILES.iter().any(|f| name == *f) {
                continue;
            }
            let target = to.join(&name);
            if entry.file_type().unwrap().is_dir() {
                copy_dir(&entry.path(), &target, false);
            } else {
                std::fs::copy(entry.path(), target).unwrap();
            }
        }
    }
    copy_dir(from, to, true);
}

/// What the snapshot knows of one entry of a folder.
#[derive(Debug, PartialEq)]
enum Entry {
    /// A regular file's bytes.
    File(Vec<u8>),
    /// A regular file larger than [`READ_LIMIT`]: its length and modification time.
    Large(u64, std::time::SystemTime),
    Folder,
    /// A symbolic link, by its target (never followed).
    Link(PathBuf),
    /// A FIFO, socket or device, by its kind only: reading a FIFO would block.
    Special(&'static str),
}

impl Entry {
    fn describe(&self) -> String {
        match self {
            Entry::File(bytes) => format!("a file of {} bytes", bytes.len()),
            Entry::Large(len, _) => format!("a file of {len} bytes"),
            Entry::Folder => "a folder".into(),
            Entry::Link(target) => format!("a link to {}", target.display()),
            Entry::Special(kind) => format!("a {kind}"),
        }
    }
}

/// Everything under `dir`, by path relative to it.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Entry>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let entry = entry.unwrap();
            let path = entry.path();
            let kind = entry.file_type().unwrap(); // of the link, not its target
            let item = if kind.is_symlink() {
                Entry::Link(std::fs::read_link(&path).unwrap())
            } else if kind.is_dir() {
                walk(root, &path, out);
                Entry::Folder
            } else if kind.is_file() {
                let meta = entry.metadata().unwrap();
                match meta.len() > READ_LIMIT {
                    true => Entry::Large(meta.len(), meta.modified().unwrap()),
                    false => Entry::File(std::fs::read(&path).unwrap()),
                }
            } else if kind.is_fifo() {
                Entry::Special("FIFO")
            } else if kind.is_socket() {
                Entry::Special("socket")
            } else {
                Entry::Special("device")
            };
            out.insert(path.strip_prefix(root).unwrap().to_owned(), item);
        }
    }
    let mut entries = BTreeMap::new();
    walk(dir, dir, &mut entries);
    entries
}

/// What changed between two snapshots, entry by entry (empty if nothing).
fn changes(before: &BTreeMap<PathBuf, Entry>, after: &BTreeMap<PathBuf, Entry>) -> String {
    let mut lines = Vec::new();
    for (path, entry) in before {
        match after.get(path) {
            None => lines.push(format!("{}: removed", path.display())),
            Some(now) if now != entry => lines.push(format!(
                "{}: changed ({} before, {} after)",
                path.display(),
                entry.describe(),
                now.describe()
            )),
            Some(_) => {}
        }
    }
    for (path, entry) in after {
        if !before.contains_key(path) {
            lines.push(format!("{}: new, {}", path.display(), entry.describe()));
        }
    }
    lines.join("; ")
}

/// `text` with each `{repeat N TEXT}` replaced by TEXT written N times (TEXT
/// is everything after the count's space up to the next `}`).
fn expand(text: &str) -> Result<String, String> {
    const OPEN: &str = "{repeat ";
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find(OPEN) {
        out.push_str(&rest[..start]);
        let after = &rest[start + OPEN.len()..];
        let end = after
            .find('}')
            .ok_or_else(|| format!("`{OPEN}` without its `}}`"))?;
        let (count, piece) = after[..end]
            .split_once(' ')
            .ok_or_else(|| format!("`{{repeat {}}}`: expected {{repeat N TEXT}}", &after[..end]))?;
        let count: usize = count
            .parse()
            .map_err(|_| format!("`{{repeat {count} …}}`: the count is not a whole number"))?;
        out.push_str(&piece.repeat(count));
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The file `name` of the case folder `case` as text, if it has one.
fn case_file(case: &Path, name: &str) -> Result<Option<String>, String> {
    match std::fs::read_to_string(case.join(name)) {
        Ok(text) => Ok(Some(text)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("cannot read `{name}`: {e}")),
    }
}

/// The arguments of a `command` or `args` file: one a line, a blank line an
/// empty argument, the file's last newline ending its last line (so an
/// empty file is no argument, and a file of one newline one empty argument);
/// each `{repeat N TEXT}` expanded.
fn argument_lines(text: &str) -> Result<Vec<String>, String> {
    if text.is_empty() {
        return Ok(Vec::new());
    }
    let text = text.strip_suffix('\n').unwrap_or(text);
    text.split('\n').map(expand).collect()
}

/// The arguments after `glint`: the case's `command`, or `render scene.toml`,
/// its `args` and `-o out.png` (unless `args` has an `-o`).
fn arguments(case: &Path) -> Result<Vec<String>, String> {
    match (case_file(case, "command")?, case_file(case, "args")?) {
        (Some(_), Some(_)) => {
            Err("has both `command` and `args`; put every argument in `command`".into())
        }
        (Some(command), None) => argument_lines(&command),
        (None, args) => {
            let mut all = vec!["render".to_owned(), "scene.toml".to_owned()];
            all.extend(argument_lines(args.as_deref().unwrap_or(""))?);
            if !all.iter().any(|a| a == "-o") {
                all.extend(["-o".to_owned(), "out.png".to_owned()]);
            }
            Ok(all)
        }
    }
}

/// Does the case's `setup` in `dir`, the copy of its folder: one directive a
/// line, its words separated by spaces (`#` starts a comment line):
///
/// - `fifo NAME`: a named pipe (`mkfifo`);
/// - `link NAME TARGET`: a symbolic link to TARGET, which need not exist;
/// - `sized NAME BYTES`: NAME (the case's own file, or a new empty one) made
///   BYTES long, the added bytes zeros and sparse (`set_len`);
/// - `expand NAME`: each `{repeat N TEXT}` in the file NAME expanded.
fn set_up(dir: &Path, setup: &str) -> Result<(), String> {
    for (number, line) in setup.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let fail = |e: &dyn std::fmt::Display| format!("setup line {}: {line:?}: {e}", number + 1);
        match words[..] {
            [] => {}
            [first, ..] if first.starts_with('#') => {}
            ["fifo", name] => {
                let made = Command::new("mkfifo")
                    .arg(dir.join(name))
                    .status()
                    .map_err(|e| fail(&e))?;
                if !made.success() {
                    return Err(fail(&format!("mkfifo failed: {made}")));
                }
            }
            ["link", name, target] => {
                std::os::unix::fs::symlink(target, dir.join(name)).map_err(|e| fail(&e))?
            }
            ["sized", name, bytes] => {
                let bytes: u64 = bytes.parse().map_err(|e| fail(&e))?;
                std::fs::OpenOptions::new()
                    .create(true)
                    .truncate(false)
                    .write(true)
                    .open(dir.join(name))
                    .and_then(|f| f.set_len(bytes))
                    .map_err(|e| fail(&e))?;
            }
            ["expand", name] => {
                let path = dir.join(name);
                let text = std::fs::read_to_string(&path).map_err(|e| fail(&e))?;
                std::fs::write(&path, expand(&text).map_err(|e| fail(&e))?)
                    .map_err(|e| fail(&e))?;
            }
            _ => return Err(fail(&"unknown directive")),
        }
    }
    Ok(())
}

/// Reads all of `from` on a thread of its own (so that a full pipe never
/// blocks the child).
fn drain(mut from: impl Read + Send + 'static) -> std::thread::JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = from.read_to_end(&mut bytes);
        bytes
    })
}

/// `glint ARGS` in `dir`, under the address-space limit, with `home` as its
/// home and `tmp` as its temporary folder, no standard input, killed past the
/// time limit (which fails the case).
fn run(dir: &Path, home: &Path, tmp: &Path, args: &[String]) -> (Output, Duration) {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .current_dir(dir)
        .env("HOME", home)
        .env("TMPDIR", tmp)
        .env_remove("XDG_CACHE_HOME")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    let stdout = drain(child.stdout.take().unwrap());
    let stderr = drain(child.stderr.take().unwrap());
    let status: ExitStatus = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            child.kill().unwrap();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let took = start.elapsed();
    let output = Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    };
    (output, took)
}

/// The texts a case's `expected` file asks for: one a non-empty line, each
/// `{repeat N TEXT}` expanded.
fn expected_texts(case: &Path) -> Result<Vec<String>, String> {
    let text = case_file(case, "expected")?.ok_or("no `expected` file")?;
    let texts: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(expand)
        .collect::<Result<_, _>>()?;
    match texts.is_empty() {
        true => Err("the `expected` file is empty".into()),
        false => Ok(texts),
    }
}

/// What is wrong with `output` as the answer to bad input: the rule of
/// [`input_error_problem`] for the first of `expected`, each of the others
/// after it on the line, and a line of at most [`LINE_BYTES`] bytes.
fn answer_problems(output: &Output, expected: &[String]) -> Vec<String> {
    let mut problems = Vec::new();
    if let Some(signal) = output.status.signal() {
        problems.push(format!("killed by signal {signal}"));
    }
    let err = stderr(output);
    if let Some(problem) = input_error_problem(output, &expected[0]) {
        problems.push(cut(&problem, 600));
    }
    let mut rest = err.split_once(expected[0].as_str()).map_or("", |(_, r)| r);
    for text in &expected[1..] {
        match rest.split_once(text.as_str()) {
            Some((_, after)) => rest = after,
            None => problems.push(format!(
                "expected {text:?} after {:?} in {}",
                cut(&expected[0], 80),
                cut(&err, 600)
            )),
        }
    }
    let line = output.stderr.strip_suffix(b"\n").unwrap_or(&output.stderr);
    if line.len() > LINE_BYTES {
        problems.push(format!(
            "the error line is {} bytes, more than {LINE_BYTES}",
            line.len()
        ));
    }
    problems
}

/// Runs one case; what is wrong with it, if anything.
fn check(case: &Path) -> Result<(), String> {
    let expected = expected_texts(case)?;
    let args = arguments(case)?;
    let root = tempfile::tempdir().unwrap();
    let (dir, home, tmp) = (
        root.path().join("case"),
        root.path().join("home"),
        root.path().join("tmp"),
    );
    copy_case(case, &dir);
    std::fs::create_dir(&home).unwrap();
    std::fs::create_dir(&tmp).unwrap();
    std::fs::write(dir.join("out.png"), PRECIOUS).unwrap();
    set_up(&dir, &case_file(case, "setup")?.unwrap_or_default())?;
    let before = snapshot(root.path());
    let (output, took) = run(&dir, &home, &tmp, &args);
    if std::env::var_os("GLINT_BAD_INPUTS_SHOW").is_some() {
        let name = case.file_name().unwrap().to_string_lossy();
        eprintln!(
            "{name} ({took:.2?}): {}",
            cut(stderr(&output).trim_end(), 300)
        );
    }
    let mut problems = Vec::new();
    if took >= TIME_LIMIT {
        problems.push(format!("still running after {took:?}, killed"));
    }
    problems.extend(answer_problems(&output, &expected));
    let changed = changes(&before, &snapshot(root.path()));
    if !changed.is_empty() {
        problems.push(format!("changed what it found: {changed}"));
    }
    match problems.is_empty() {
        true => Ok(()),
        false => Err(problems.join("; ")),
    }
}

/// At most `n` characters of `text`, with "…" where it was cut.
fn cut(text: &str, n: usize) -> String {
    match text.char_indices().nth(n) {
        Some((i, _)) => format!("{}…", &text[..i]),
        None => text.to_owned(),
    }
}

#[test]
fn every_bad_input_gives_one_clear_error_and_changes_nothing() {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    assert!(cases.len() >= 90, "the corpus has {} cases", cases.len());
    let mut failures = Vec::new();
    let mut commands = BTreeSet::new();
    for case in &cases {
        let name = case.file_name().unwrap().to_string_lossy().into_owned();
        if let Ok(args) = arguments(case) {
            commands.extend(args.first().cloned());
        }
        if let Err(why) = check(case) {
            failures.push(format!("{name}: {why}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
    for command in COMMANDS {
        assert!(commands.contains(command), "no case runs glint {command}");
    }
    for class in CLASSES {
        assert!(
            cases.iter().any(|c| c
                .file_name()
                .unwrap()
                .to_string_lossy()
                .contains(&format!("-{class}-"))),
            "no case of the class {class:?}"
        );
    }
}

#[test]
fn the_runner_reads_commands_and_setups_as_documented() {
    assert_eq!(expand("a{repeat 3 xy}b{repeat 0 z}").unwrap(), "axyxyxyb");
    assert!(expand("{repeat many x}").is_err());
    assert!(expand("{repeat 3 x").is_err());
    assert_eq!(argument_lines("").unwrap(), Vec::<String>::new());
    assert_eq!(argument_lines("\n").unwrap(), [""]);
    assert_eq!(
        argument_lines("diff\n\nb.png\n").unwrap(),
        ["diff", "", "b.png"]
    );
    assert_eq!(argument_lines("stress").unwrap(), ["stress"]);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), "name = \"{repeat 4 ab}\"\n").unwrap();
    set_up(
        d,
        "# a comment\nfifo pipe\nlink dangling nowhere\nsized big 100000000\nsized s.toml 30\n",
    )
    .unwrap();
    assert!(set_up(d, "expand s.toml\n").is_ok());
    std::fs::create_dir(d.join("empty")).unwrap();
    assert!(set_up(d, "unlink x\n").is_err());
    let files = snapshot(d);
    assert_eq!(files[Path::new("pipe")], Entry::Special("FIFO"));
    assert_eq!(files[Path::new("dangling")], Entry::Link("nowhere".into()));
    assert!(matches!(
        files[Path::new("big")],
        Entry::Large(100_000_000, _)
    ));
    assert_eq!(files[Path::new("empty")], Entry::Folder);
    // 23 bytes made 30 by `sized` (7 zeros), then expanded.
    let mut expanded = b"name = \"abababab\"\n".to_vec();
    expanded.extend([0; 7]);
    assert_eq!(files[Path::new("s.toml")], Entry::File(expanded));
    std::fs::write(d.join("new"), "").unwrap();
    assert_eq!(changes(&files, &snapshot(d)), "new: new, a file of 0 bytes");

    let case = tempfile::tempdir().unwrap();
    let c = case.path();
    let default = ["render", "scene.toml", "-o", "out.png"];
    assert_eq!(arguments(c).unwrap(), default);
    std::fs::write(c.join("args"), "--spp\n4\n").unwrap();
    assert_eq!(
        arguments(c).unwrap(),
        ["render", "scene.toml", "--spp", "4", "-o", "out.png"]
    );
    std::fs::write(c.join("args"), "-o\nx.exr\n").unwrap();
    assert_eq!(
        arguments(c).unwrap(),
        ["render", "scene.toml", "-o", "x.exr"]
    );
    std::fs::write(c.join("command"), "stress\n").unwrap();
    assert!(arguments(c).is_err(), "`command` and `args` together");
    std::fs::remove_file(c.join("args")).unwrap();
    assert_eq!(arguments(c).unwrap(), ["stress"]);
}
