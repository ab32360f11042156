// Test helper: renders the golden scene (with its structure overlay when the
// fourth argument is "structure") and writes the raw RGBA bytes to the file
// named by argv[1] (used to compare renders across processes).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "crumple/render/osmesa_renderer.hpp"
#include "render_test_scenes.hpp"

int main(int argc, char** argv) {
  const bool structure = argc == 5 && std::strcmp(argv[4], "structure") == 0;
  if (argc != 4 && !structure) {
    std::fprintf(stderr, "usage: render_dump OUT.rgba WIDTH HEIGHT [structure]\n");
    return 2;
  }
  try {
    namespace test = crumple::render::test;
    const int w = std::atoi(argv[2]), h = std::atoi(argv[3]);
    crumple::render::OsmesaRenderer renderer(w, h);
    const auto sheet = test::bentSceneSheet();
    const auto overlay = test::bentSheetStructure(sheet);
    const auto img = renderer.render(test::bentScene(w, h), sheet, structure ? &overlay : nullptr);
    std::FILE* f = std::fopen(argv[1], "wb");
    if (!f) return 1;
    const bool ok = std::fwrite(img.pixels.data(), 1, img.pixels.size(), f) == img.pixels.size();
    return (std::fclose(f) == 0 && ok) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_dump: %s\n", e.what());
    return 1;
  }
}
