#pragma once
// Private: the scene file's parser (docs/SCENE.md is the schema). One
// SceneParser walks the tables in a fixed order (parse()); its members are
// defined by concept:
//   scene.cpp           the parse order, [scene], [output], the public entry points
//   scene_sheet.cpp     [sheet] (rectangle, outline, pattern mesh), [paper]
//   scene_handles.cpp   [[handles]]
//   scene_view.cpp      [camera], [[lights]], [environment], [ground], [[props]]
//   scene_contacts.cpp  [friction], [[colliders]], [contact]
//   scene_model.cpp     [model], [sim], [tear], [sound]: the modules' parameters
//   scene_air.cpp       [air]
#include <string>
#include <string_view>
#include <vector>

#include "crumple/io/scene.hpp"
#include "toml_reader.hpp"

namespace crumple::io::detail {

inline constexpr double kPi = 3.14159265358979323846;

class SceneParser {
 public:
  SceneParser(std::string_view text, const std::string& file, const std::string& baseDir,
              bool checkFiles);

  SceneSpec parse();

 private:
  double mpu() const { return spec_.metresPerUnit; }
  std::string defaultName() const;
  // A path relative to the scene's folder.
  std::string resolvePath(const std::string& path) const;

  // scene.cpp
  void parseScene(const toml::table* table);
  void parseOutput(const toml::table* table);

  // scene_sheet.cpp
  void parseSheet(const toml::table& table);
  void checkSheetSize(const TableReader& r, const SheetSpec& s) const;
  std::vector<Vec2> parseOutline(const TableReader& r) const;
  std::vector<std::string> availablePresets() const;
  template <class Fail>
  PaperPreset findPreset(const std::string& name, Fail&& fail) const;
  void parsePaper(const toml::table* table);

  // scene_handles.cpp
  void parseHandles(const TableReader& root);

  // scene_view.cpp
  void parseCamera(const toml::table* table);
  void parseLights(const TableReader& root);
  void parseEnvironment(const toml::table* table);
  void parseGround(const toml::table* table);
  void parseProps(const TableReader& root);

  // scene_contacts.cpp
  void parseFriction(const toml::table* table);
  void parseColliders(const TableReader& root);
  void parseContact(const toml::table* table);

  // scene_model.cpp
  void parseTear(const toml::table* table);
  void parseSound(const toml::table* table);
  void parseSim(const toml::table* table);
  void parseModel(const toml::table* table);

  // scene_air.cpp
  void parseAir(const toml::table* table);

  std::string file_;
  std::string baseDir_;
  bool checkFiles_ = true;
  toml::table root_;
  SceneSpec spec_;
};

}  // namespace crumple::io::detail
