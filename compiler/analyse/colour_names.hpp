// colour_names — the colour names the benchmark can draw, and their RGB values.
//
// The AutumnBench harness draws frames with matplotlib, which knows the CSS
// named colours (CSS Color Module Level 4: the 16 basic names, the X11 extended
// set with both spellings of grey, and rebeccapurple); any other name is drawn in
// the background colour `black`. A program may paint with any string, and the
// frames keep it as text; this table is what turns a name into a pixel
// (harness/render) and what tells a colour from a typo (analyse's warnings).
#pragma once
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace autumn {

struct NamedColour {
  const char* name;  // lower-case
  uint32_t rgb;      // 0xRRGGBB
};

// Every known name, sorted by name.
const std::vector<NamedColour>& named_colours();
// The RGB value of a (lower-case) colour name; nullopt for unknown names.
std::optional<uint32_t> colour_rgb(std::string_view name);
// The known name closest to `name` by edit distance (for "did you mean"), if one
// is within two edits.
std::optional<std::string_view> closest_colour(std::string_view name);

}  // namespace autumn
