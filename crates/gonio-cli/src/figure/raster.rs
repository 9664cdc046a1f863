//! SVG → PNG with resvg, with the font embedded in the binary (see `fonts/README.md`), so PNG text looks
//! the same on every machine whether or not it has fonts installed.

use resvg::{tiny_skia, usvg};

/// DejaVu Sans (Bitstream Vera licence, `fonts/LICENSE-DejaVu.txt`).
const FONT: &[u8] = include_bytes!("../../fonts/DejaVuSans.ttf");

/// Rasterise an SVG document written by [`super::svg::Svg`] into PNG bytes at its own pixel size.
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, String> {
    let mut options = usvg::Options { font_family: "DejaVu Sans".into(), ..usvg::Options::default() };
    options.fontdb_mut().load_font_data(FONT.to_vec());
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| format!("the figure is not valid SVG ({e}); this is a bug"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("the figure has no pixels")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::identity(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| format!("PNG encoding failed: {e}"))
}

/// An RGB image (row-major, top row first, 8-bit sRGB per channel) as PNG bytes.
pub fn rgb_to_png(width: u32, height: u32, rgb: &[[u8; 3]]) -> Result<Vec<u8>, String> {
    debug_assert_eq!(rgb.len(), (width * height) as usize);
    let mut pixmap = tiny_skia::Pixmap::new(width, height).ok_or("an image with no pixels")?;
    for (px, c) in pixmap.pixels_mut().iter_mut().zip(rgb) {
        *px = tiny_skia::PremultipliedColorU8::from_rgba(c[0], c[1], c[2], 255).expect("opaque colours are premultiplied");
    }
    pixmap.encode_png().map_err(|e| format!("PNG encoding failed: {e}"))
}
