// render_images — frames as pictures: PNG files and animated GIFs.
//
// A frame is first turned into a Picture: one 0xRRGGBB value per cell, by the
// benchmark's colour names (compiler/analyse/colour_names: the CSS named colours
// matplotlib knows; an unknown name is drawn in the benchmark harness's background
// colour, black). A Picture is then drawn into an Image, `scale` pixels per cell,
// optionally with one-pixel grid lines between cells; several Images can be laid
// out in rows (a strip of frames, or expected | got | difference).
//
// Encoding and decoding go through libpng (the simplified png_image API) and
// giflib; nothing here knows a file format's bytes. Every failure (a path that
// cannot be written, more than 256 colours in a GIF, a file that is not an image)
// is a std::runtime_error with a one-line reason. The read_* functions exist for
// the tests, which decode what was written and compare pixels. Captions under
// panels are drawn with FreeType from the DejaVu Sans font file.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/frame.hpp"

namespace autumn {

// One colour per cell, row-major.
struct Picture {
  int width = 0, height = 0;
  std::vector<uint32_t> rgb;  // 0xRRGGBB
  uint32_t at(int x, int y) const { return rgb[static_cast<size_t>(y) * width + x]; }
};

// RGB pixels, row-major, 3 bytes a pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  uint32_t at(int x, int y) const;
  void set(int x, int y, uint32_t rgb);
  bool operator==(const Image&) const = default;
};

constexpr uint32_t kUnknownColourRgb = 0x000000;  // the benchmark harness's background
constexpr uint32_t kMaskRgb = 0x708090;          // slategrey: MARAProtocol's masked cells

// The RGB value a frame shows for a colour name (lower-cased first).
uint32_t cell_rgb(const std::string& name);
Picture picture_of(const Frame& frame, const Palette& palette);
// Rows in the trace format: colour names separated by single spaces.
Picture picture_of_rows(const std::vector<std::string>& rows);

struct DrawOptions {
  int scale = 16;           // pixels per cell side
  bool grid_lines = false;  // a one-pixel dark line between cells
};
Image draw(const Picture& p, const DrawOptions& o);
// A panel with its caption: a white band kCaptionHeight pixels high under it,
// `text` in black (FreeType, DejaVu Sans; two colours, so a GIF stays exact).
// Text wider than the panel is cut and ends in "...". Throws std::runtime_error
// when the font cannot be loaded (its path is fixed when the project is built).
constexpr int kCaptionHeight = 15;
Image captioned(const Image& panel, const std::string& text);
// Images laid out left to right, `columns` per row, `gap` pixels of gap_rgb between them.
Image tile(const std::vector<Image>& images, int columns, int gap = 4, uint32_t gap_rgb = 0xffffff);

void write_png(const std::string& path, const Image& image);
// An animated GIF that loops forever, each frame shown `delay_ms` milliseconds
// (GIF counts hundredths of a second). All frames must have one size.
void write_gif(const std::string& path, const std::vector<Image>& frames, int delay_ms);

Image read_png(const std::string& path);
std::vector<Image> read_gif(const std::string& path);

}  // namespace autumn
