//! Builds a random motor from the add-on's own generator and exports it as glTF and PLY, one
//! file per part, with its ground truth (`attributes.json`).
//!
//! Usage: `cargo run --release --example random_motor -- SEED OUT_DIR`

use motorgen::{Detail, Format, ParamSpace, build, export::write_motor};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [seed, out] = args.as_slice() else {
        return Err("usage: random_motor SEED OUT_DIR".into());
    };
    // every parameter drawn as the add-on's random mode draws it
    let params = ParamSpace::addon().sample(seed.parse()?)?;
    let motor = build(&params, Detail::Normal);
    let written = write_motor(&motor, out.as_ref(), &[Format::Glb, Format::Ply], true)?;
    println!(
        "motor {} ({} parts): {} files in {out}",
        params.variant(),
        motor.parts.len(),
        written.len()
    );
    for gear in &motor.attributes.gears {
        println!("  gear centre {:?}, axis {:?}", gear.centre, gear.axis);
    }
    Ok(())
}
