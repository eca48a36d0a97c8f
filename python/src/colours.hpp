// colours — one colour vocabulary for every observation the package returns.
//
// Frames hold per-environment palette ids (runtime/frame.hpp); Python callers
// get uint8 arrays whose ids mean the same colour everywhere in the process:
// ids 0..39 are the AutumnBench colour table (color_dict.yaml, built into
// harness/agent's ColourTable; 0 is "transparent"), and colours outside it get
// the next free id, in order of first appearance, for the life of the process.
// More than 256 colours is an error. PaletteMap caches one environment's
// palette -> vocabulary map, keyed by the palette's version.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/frame.hpp"

namespace autumn::py {

uint8_t colour_id(const std::string& name);  // throws std::length_error past 256 colours
std::vector<std::string> colour_names();      // index = id

class PaletteMap {
 public:
  const std::vector<uint8_t>& of(const Palette& p);
  // Writes frame.size^2 ids, row-major.
  void paint(const Frame& f, const Palette& p, uint8_t* out);

 private:
  uint64_t version_ = ~0ull;
  size_t size_ = 0;
  std::vector<uint8_t> ids_;
};

}  // namespace autumn::py
