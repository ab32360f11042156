// Test helper: renders the golden scene and writes the raw RGBA bytes to the
// file named by argv[1] (used to compare renders across processes).
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "crumple/render/osmesa_renderer.hpp"
#include "render_test_scenes.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: render_dump OUT.rgba WIDTH HEIGHT\n");
    return 2;
  }
  try {
    const int w = std::atoi(argv[2]), h = std::atoi(argv[3]);
    crumple::render::OsmesaRenderer renderer(w, h);
    const auto img = renderer.render(crumple::render::test::bentScene(w, h),
                                     crumple::render::test::bentSceneSheet());
    std::FILE* f = std::fopen(argv[1], "wb");
    if (!f) return 1;
    const bool ok = std::fwrite(img.pixels.data(), 1, img.pixels.size(), f) == img.pixels.size();
    return (std::fclose(f) == 0 && ok) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_dump: %s\n", e.what());
    return 1;
  }
}
