#include "harness/render_images.hpp"

#include <fcntl.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include <gif_lib.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "compiler/analyse/colour_names.hpp"

namespace autumn {

uint32_t Image::at(int x, int y) const {
  const uint8_t* p = &pixels[(static_cast<size_t>(y) * width + x) * 3];
  return (uint32_t{p[0]} << 16) | (uint32_t{p[1]} << 8) | p[2];
}

void Image::set(int x, int y, uint32_t rgb) {
  uint8_t* p = &pixels[(static_cast<size_t>(y) * width + x) * 3];
  p[0] = static_cast<uint8_t>(rgb >> 16);
  p[1] = static_cast<uint8_t>(rgb >> 8);
  p[2] = static_cast<uint8_t>(rgb);
}

uint32_t cell_rgb(const std::string& name) {
  return colour_rgb(lower_ascii(name)).value_or(kUnknownColourRgb);
}

Picture picture_of(const Frame& frame, const Palette& palette) {
  Picture p;
  p.width = p.height = frame.size;
  std::vector<uint32_t> of_id(palette.size());
  for (size_t i = 0; i < palette.size(); ++i) of_id[i] = cell_rgb(palette.name(static_cast<uint16_t>(i)));
  for (uint16_t c : frame.cells) p.rgb.push_back(of_id[c]);
  return p;
}

Picture picture_of_rows(const std::vector<std::string>& rows) {
  std::vector<std::vector<uint32_t>> cells;
  Picture p;
  for (const std::string& row : rows) {
    std::istringstream in(row);
    cells.emplace_back();
    for (std::string name; in >> name;) cells.back().push_back(cell_rgb(name));
    p.width = std::max(p.width, static_cast<int>(cells.back().size()));
  }
  p.height = static_cast<int>(rows.size());
  for (auto& row : cells) {
    row.resize(static_cast<size_t>(p.width), kUnknownColourRgb);
    p.rgb.insert(p.rgb.end(), row.begin(), row.end());
  }
  return p;
}

namespace {

Image blank(int width, int height, uint32_t rgb) {
  Image im;
  im.width = width;
  im.height = height;
  im.pixels.resize(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) im.set(x, y, rgb);
  return im;
}

void blit(Image& dst, const Image& src, int x0, int y0) {
  for (int y = 0; y < src.height; ++y)
    std::memcpy(&dst.pixels[(static_cast<size_t>(y0 + y) * dst.width + x0) * 3],
                &src.pixels[static_cast<size_t>(y) * src.width * 3], static_cast<size_t>(src.width) * 3);
}

constexpr uint32_t kGridLineRgb = 0x303030;

}  // namespace

Image draw(const Picture& p, const DrawOptions& o) {
  const int s = std::max(1, o.scale);
  const int line = o.grid_lines ? 1 : 0;
  Image im = blank(p.width * s + line, p.height * s + line, kGridLineRgb);
  for (int cy = 0; cy < p.height; ++cy)
    for (int cx = 0; cx < p.width; ++cx)
      for (int y = line; y < s; ++y)
        for (int x = line; x < s; ++x) im.set(cx * s + x, cy * s + y, p.at(cx, cy));
  return im;
}

// ---------------------------------------------------------------------------- captions

namespace {

// The font, loaded on first use and kept (FreeType's library and face are not
// thread-safe: captions are drawn under a mutex).
struct CaptionFont {
  FT_Library lib = nullptr;
  FT_Face face = nullptr;
  std::string error;
  CaptionFont() {
    if (FT_Init_FreeType(&lib)) {
      error = "cannot start FreeType";
      return;
    }
    if (FT_New_Face(lib, AUTUMN_CAPTION_FONT, 0, &face) || FT_Set_Pixel_Sizes(face, 0, 11)) {
      error = std::string("cannot load the caption font ") + AUTUMN_CAPTION_FONT +
              " (Debian's fonts-dejavu-core; scripts/bootstrap.sh installs it)";
      face = nullptr;
    }
  }
};

// The width in pixels of `text` (its glyphs' advances).
int text_width(FT_Face face, const std::string& text) {
  int w = 0;
  for (unsigned char c : text)
    if (!FT_Load_Char(face, c < 0x80 ? c : '?', FT_LOAD_DEFAULT)) w += static_cast<int>(face->glyph->advance.x >> 6);
  return w;
}

// Draws `text` from pen position x on baseline y, black where a glyph covers at
// least half a pixel (two colours: a GIF's palette stays exact).
void draw_text(Image& im, FT_Face face, const std::string& text, int x, int baseline) {
  for (unsigned char c : text) {
    if (FT_Load_Char(face, c < 0x80 ? c : '?', FT_LOAD_RENDER)) continue;
    const FT_GlyphSlot g = face->glyph;
    for (unsigned row = 0; row < g->bitmap.rows; ++row)
      for (unsigned col = 0; col < g->bitmap.width; ++col) {
        const int px = x + g->bitmap_left + static_cast<int>(col), py = baseline - g->bitmap_top + static_cast<int>(row);
        if (px >= 0 && py >= 0 && px < im.width && py < im.height &&
            g->bitmap.buffer[row * static_cast<unsigned>(g->bitmap.pitch) + col] >= 128)
          im.set(px, py, 0x000000);
      }
    x += static_cast<int>(g->advance.x >> 6);
  }
}

}  // namespace

Image captioned(const Image& panel, const std::string& text) {
  static CaptionFont font;
  static std::mutex mu;
  std::lock_guard<std::mutex> lock(mu);
  if (!font.face) throw std::runtime_error(font.error);
  Image out = blank(panel.width, panel.height + kCaptionHeight, 0xffffff);
  blit(out, panel, 0, 0);
  const int room = panel.width - 4;
  std::string shown = text;
  if (text_width(font.face, shown) > room) {  // as much as fits, then "..."
    const int dots = text_width(font.face, "...");
    while (!shown.empty() && text_width(font.face, shown) + dots > room) shown.pop_back();
    shown += "...";
  }
  draw_text(out, font.face, shown, 2, panel.height + kCaptionHeight - 4);
  return out;
}

Image tile(const std::vector<Image>& images, int columns, int gap, uint32_t gap_rgb) {
  if (images.empty()) return {};
  columns = std::max(1, std::min<int>(columns, static_cast<int>(images.size())));
  const int rows = (static_cast<int>(images.size()) + columns - 1) / columns;
  int cell_w = 0, cell_h = 0;
  for (const Image& im : images) cell_w = std::max(cell_w, im.width), cell_h = std::max(cell_h, im.height);
  Image out = blank(columns * cell_w + (columns - 1) * gap, rows * cell_h + (rows - 1) * gap, gap_rgb);
  for (size_t i = 0; i < images.size(); ++i)
    blit(out, images[i], static_cast<int>(i % columns) * (cell_w + gap), static_cast<int>(i / columns) * (cell_h + gap));
  return out;
}

// ---------------------------------------------------------------------------- PNG

void write_png(const std::string& path, const Image& image) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.pixels.data(), 0, nullptr))
    throw std::runtime_error("cannot write " + path + ": " + png.message);
}

Image read_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw std::runtime_error("cannot read " + path + ": " + png.message);
  png.format = PNG_FORMAT_RGB;
  Image im;
  im.width = static_cast<int>(png.width);
  im.height = static_cast<int>(png.height);
  im.pixels.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, im.pixels.data(), 0, nullptr))
    throw std::runtime_error("cannot read " + path + ": " + png.message);
  return im;
}

// ---------------------------------------------------------------------------- GIF

namespace {

std::string gif_error(const std::string& what, const std::string& path, int code) {
  const char* msg = GifErrorString(code);
  return what + " " + path + ": " + (msg ? msg : "giflib error " + std::to_string(code));
}

struct GifWriter {
  GifFileType* gif = nullptr;
  std::string path;
  explicit GifWriter(const std::string& p) : path(p) {
    int err = 0;
    const int fd = open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);  // giflib's own open makes it 0600
    if (fd < 0) throw std::runtime_error("cannot write " + p + ": " + std::strerror(errno));
    gif = EGifOpenFileHandle(fd, &err);
    if (!gif) {
      ::close(fd);
      throw std::runtime_error(gif_error("cannot write", p, err));
    }
    EGifSetGifVersion(gif, true);
  }
  ~GifWriter() {
    int err = 0;
    if (gif) EGifCloseFile(gif, &err);
  }
  void check(int status) const {
    if (status != GIF_OK) throw std::runtime_error(gif_error("cannot write", path, gif->Error));
  }
  void close() {
    int err = 0;
    int status = EGifCloseFile(gif, &err);
    gif = nullptr;
    if (status != GIF_OK) throw std::runtime_error(gif_error("cannot write", path, err));
  }
};

// Every colour of every frame, in first-seen order (at most 256).
std::map<uint32_t, int> colour_indices(const std::vector<Image>& frames, const std::string& path) {
  std::map<uint32_t, int> index;
  for (const Image& f : frames)
    for (int y = 0; y < f.height; ++y)
      for (int x = 0; x < f.width; ++x)
        if (index.emplace(f.at(x, y), static_cast<int>(index.size())).second && index.size() > 256)
          throw std::runtime_error("cannot write " + path + ": a GIF holds at most 256 colours");
  return index;
}

void put_loop_forever(GifWriter& w) {
  const unsigned char app[] = "NETSCAPE2.0";
  const unsigned char loop[] = {1, 0, 0};
  w.check(EGifPutExtensionLeader(w.gif, APPLICATION_EXT_FUNC_CODE));
  w.check(EGifPutExtensionBlock(w.gif, 11, app));
  w.check(EGifPutExtensionBlock(w.gif, 3, loop));
  w.check(EGifPutExtensionTrailer(w.gif));
}

void put_frame(GifWriter& w, const Image& f, const std::map<uint32_t, int>& index, int delay_ms) {
  GraphicsControlBlock gcb{};
  gcb.DisposalMode = DISPOSE_DO_NOT;
  gcb.DelayTime = std::max(1, (delay_ms + 5) / 10);
  gcb.TransparentColor = NO_TRANSPARENT_COLOR;
  GifByteType ext[4];
  size_t n = EGifGCBToExtension(&gcb, ext);
  w.check(EGifPutExtension(w.gif, GRAPHICS_EXT_FUNC_CODE, static_cast<int>(n), ext));
  w.check(EGifPutImageDesc(w.gif, 0, 0, f.width, f.height, false, nullptr));
  std::vector<GifPixelType> line(static_cast<size_t>(f.width));
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) line[x] = static_cast<GifPixelType>(index.at(f.at(x, y)));
    w.check(EGifPutLine(w.gif, line.data(), f.width));
  }
}

}  // namespace

void write_gif(const std::string& path, const std::vector<Image>& frames, int delay_ms) {
  if (frames.empty()) throw std::runtime_error("cannot write " + path + ": no frames");
  for (const Image& f : frames)
    if (f.width != frames[0].width || f.height != frames[0].height)
      throw std::runtime_error("cannot write " + path + ": frames of different sizes");
  const std::map<uint32_t, int> index = colour_indices(frames, path);
  int size = 2;
  while (size < static_cast<int>(index.size())) size *= 2;
  std::vector<GifColorType> colours(static_cast<size_t>(size));
  for (const auto& [rgb, i] : index)
    colours[i] = GifColorType{static_cast<GifByteType>(rgb >> 16), static_cast<GifByteType>(rgb >> 8),
                              static_cast<GifByteType>(rgb)};
  std::unique_ptr<ColorMapObject, void (*)(ColorMapObject*)> map(GifMakeMapObject(size, colours.data()),
                                                                 GifFreeMapObject);
  if (!map) throw std::runtime_error("cannot write " + path + ": out of memory");
  GifWriter w(path);
  w.check(EGifPutScreenDesc(w.gif, frames[0].width, frames[0].height, map->BitsPerPixel, 0, map.get()));
  put_loop_forever(w);
  for (const Image& f : frames) put_frame(w, f, index, delay_ms);
  w.close();
}

std::vector<Image> read_gif(const std::string& path) {
  int err = 0;
  GifFileType* gif = DGifOpenFileName(path.c_str(), &err);
  if (!gif) throw std::runtime_error(gif_error("cannot read", path, err));
  std::unique_ptr<GifFileType, void (*)(GifFileType*)> owner(gif, [](GifFileType* g) {
    int e = 0;
    DGifCloseFile(g, &e);
  });
  if (DGifSlurp(gif) != GIF_OK) throw std::runtime_error(gif_error("cannot read", path, gif->Error));
  std::vector<Image> frames;
  Image canvas = blank(gif->SWidth, gif->SHeight, 0);
  for (int i = 0; i < gif->ImageCount; ++i) {
    const SavedImage& s = gif->SavedImages[i];
    const ColorMapObject* map = s.ImageDesc.ColorMap ? s.ImageDesc.ColorMap : gif->SColorMap;
    if (!map) throw std::runtime_error("cannot read " + path + ": a frame without a colour map");
    if (s.ImageDesc.Left + s.ImageDesc.Width > canvas.width || s.ImageDesc.Top + s.ImageDesc.Height > canvas.height)
      throw std::runtime_error("cannot read " + path + ": a frame outside the screen");
    for (int y = 0; y < s.ImageDesc.Height; ++y)
      for (int x = 0; x < s.ImageDesc.Width; ++x) {
        const int c = s.RasterBits[static_cast<size_t>(y) * s.ImageDesc.Width + x];
        if (c >= map->ColorCount) throw std::runtime_error("cannot read " + path + ": colour index out of range");
        const GifColorType& g = map->Colors[c];
        canvas.set(s.ImageDesc.Left + x, s.ImageDesc.Top + y, (uint32_t{g.Red} << 16) | (uint32_t{g.Green} << 8) | g.Blue);
      }
    frames.push_back(canvas);
  }
  return frames;
}

}  // namespace autumn
