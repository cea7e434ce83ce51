//! Build the mip chain of a built-in texture and print each level's size and
//! the time taken.
//!
//! `cargo run --release --example 01_build_mips -- [builtin:zoneplate:4096] [box|kaiser|...] [srgb|linear]`
use std::time::Instant;

use parvo::mip::{self, MipOptions};
use parvo::{ColorSpace, builtin};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args
        .next()
        .unwrap_or_else(|| "builtin:zoneplate:4096".into());
    let filter = args.next().unwrap_or_else(|| "box".into()).parse()?;
    let tex = builtin::load(&name)?;
    let tex = match args.next().as_deref() {
        Some(cs) => {
            let cs: ColorSpace = cs.parse()?;
            let f = tex.format();
            tex.reinterpret(parvo::Format {
                color_space: cs,
                ..f
            })?
        }
        None => tex,
    };
    println!("{name}: {}x{} {}", tex.width(), tex.height(), tex.format());
    for _ in 0..3 {
        let t = Instant::now();
        let chain = mip::build(tex.clone(), &MipOptions::with_filter(filter))?;
        println!(
            "{filter}: {} levels in {:.2} ms",
            chain.len(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
