// What crumple reads from an AOV EXR (exporters::readExrChannels), as the
// expectations of tests/blender/aov_compositor.py: "size W H", for every
// Blender pass of the file "pass NAME CHANNELS"; then "pixel NAME X Y V..." at the sheet
// pixel nearest the image's centre (IndexOB.X == 1) and at pixel (0, 0).
// Blender's pass names: R, G, B, A are "Combined" (A also "Alpha"), Z is
// "Depth", "layer.C" is "layer".
//
//   exr_probe FRAME.exr > EXPECT.txt
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "crumple/exporters/exr.hpp"

namespace {

// Blender's pass of a channel, and the channel's index within it.
std::pair<std::string, int> blenderPass(const std::string& channel) {
  if (channel == "R" || channel == "G" || channel == "B" || channel == "A")
    return {"Combined", static_cast<int>(std::string("RGBA").find(channel[0]))};
  if (channel == "Z") return {"Depth", 0};
  const std::size_t dot = channel.rfind('.');
  const std::string layer = channel.substr(0, dot);
  const char c = channel[dot + 1];
  const std::string order = c == 'R' || c == 'G' || c == 'B' ? "RGB" : "XYZ";
  return {layer, static_cast<int>(order.find(c))};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: exr_probe FRAME.exr\n");
    return 2;
  }
  try {
    const crumple::ImageChannels image = crumple::exporters::readExrChannels(argv[1]);
    std::map<std::string, std::vector<const crumple::ImageChannel*>> passes;
    for (const crumple::ImageChannel& c : image.channels) {
      const auto [pass, index] = blenderPass(c.name);
      auto& slots = passes[pass];
      if (slots.size() <= static_cast<std::size_t>(index))
        slots.resize(static_cast<std::size_t>(index) + 1, nullptr);
      slots[static_cast<std::size_t>(index)] = &c;
    }
    std::printf("size %d %d\n", image.width, image.height);
    for (const auto& [pass, slots] : passes)
      std::printf("pass %s %zu\n", pass.c_str(), slots.size());
    const crumple::ImageChannel* object = image.find("IndexOB.X");
    int px = 0, py = 0;
    double best = 1e300;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * image.width + x;
        const double d = std::hypot(x - 0.5 * image.width, y - 0.5 * image.height);
        if (object && object->pixels[i] == 1.0f && d < best) {
          best = d;
          px = x;
          py = y;
        }
      }
    for (const auto& [x, y] : {std::pair{px, py}, std::pair{0, 0}})
      for (const auto& [pass, slots] : passes) {
        std::printf("pixel %s %d %d", pass.c_str(), x, y);
        for (const crumple::ImageChannel* c : slots)
          std::printf(" %.9g", c ? c->pixels[static_cast<std::size_t>(y) * image.width + x] : 0.0);
        std::printf("\n");
      }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exr_probe: %s\n", e.what());
    return 2;
  }
}
