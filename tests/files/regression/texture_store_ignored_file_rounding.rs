//! `TextureStore::from_loaded` (what `parvo render` and `parvo tradeoff`
//! sample through) built its chain options with the GPU's round-down rule
//! whatever the file said, so an OpenEXR chain written with
//! `--rounding up` (OpenEXR's ROUND_UP, as maketx can write) was refused:
//! "level 1 is 19x19 …, expected 18x18". The store now keeps the file's
//! rounding, as `io::load_chain` always did.

use parvo::store::TextureStore;

use super::util::{ok, parvo, s};

#[test]
fn a_rounded_up_exr_chain_is_sampled_by_the_store_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("up.exr");
    ok(&parvo(&[
        "mip",
        "builtin:photo:37",
        "-o",
        s(&exr),
        "--rounding",
        "up",
    ]));

    // The library: the store's chain is the file's seven levels, sizes
    // ceil(37 / 2^k) as OpenEXR's ROUND_UP defines them.
    let store = TextureStore::load(s(&exr), &parvo::io::Limits::default()).unwrap();
    let chain = store.chain().expect("the file's own levels are the chain");
    let sizes: Vec<_> = chain
        .levels()
        .iter()
        .map(|l| (l.width(), l.height()))
        .collect();
    let want: Vec<_> = (0..7)
        .map(|k| {
            let n = 37u32.div_ceil(1 << k);
            (n, n)
        })
        .collect();
    assert_eq!(sizes, want);
    // And the same chain as the sampling loader's.
    let direct = parvo::io::load_chain(s(&exr), &parvo::io::Limits::default()).unwrap();
    assert_eq!(direct.levels().len(), chain.levels().len());
    for (a, b) in direct.levels().iter().zip(chain.levels()) {
        assert_eq!(a.texels(), b.texels());
    }

    // The command line: render samples it.
    let png = dir.path().join("r.png");
    ok(&parvo(&[
        "render",
        "--texture",
        s(&exr),
        "--size",
        "64x48",
        "--filter",
        "trilinear",
        "-o",
        s(&png),
    ]));
}
