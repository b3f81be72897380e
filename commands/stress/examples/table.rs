//! The stress table: `cargo run --release -p glint-stress --example table -- [GRID] [no-joints]`.

fn main() {
    let mut args = std::env::args().skip(1);
    let grid = args.next().and_then(|a| a.parse().ok()).unwrap_or(16);
    let joints = args.next().as_deref() != Some("no-joints");
    let rows = glint_stress::run(glint_stress::Settings { grid, joints });
    print!("{}", glint_stress::table(&rows));
}
