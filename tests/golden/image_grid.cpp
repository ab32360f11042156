// PNG frames laid out as a labelled grid (render::makeContactSheet), for the
// side-by-side figures of the docs (scripts/refine-contact-sheet.sh).
//
//   image_grid OUT.png COLUMNS CELL_WIDTH LABEL=FRAME.png [LABEL=FRAME.png ...]
//
// LABEL is the whole number printed under the cell; the cells run left to
// right, then top to bottom.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "crumple/exporters/png.hpp"
#include "crumple/render/contact_sheet.hpp"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: image_grid OUT.png COLUMNS CELL_WIDTH LABEL=FRAME.png [...]\n");
    return 2;
  }
  try {
    std::vector<std::pair<int, crumple::ImageRGBA8>> cells;
    for (int i = 4; i < argc; ++i) {
      const std::string arg = argv[i];
      const std::size_t eq = arg.find('=');
      if (eq == std::string::npos) throw std::runtime_error("'" + arg + "' is not LABEL=FRAME.png");
      cells.emplace_back(std::stoi(arg.substr(0, eq)),
                         crumple::exporters::readPng(arg.substr(eq + 1)));
    }
    crumple::exporters::writePng(
        argv[1], crumple::render::makeContactSheet(cells, std::atoi(argv[2]), std::atoi(argv[3])));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "image_grid: %s\n", e.what());
    return 1;
  }
  return 0;
}
