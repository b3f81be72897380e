//! The stress table: `cargo run --release -p glint-stress --example table -- [GRID] [joints]`.

fn main() {
    let mut args = std::env::args().skip(1);
    let grid = args.next().and_then(|a| a.parse().ok()).unwrap_or(16);
    let joints = args.next().as_deref() == Some("joints");
    print!("{}", glint_stress::table(&glint_stress::run(grid, joints)));
}
