#pragma once
// The scene parser's tests share these: parsing a scene text named
// test.toml (paths resolve against tests/io/data) and the one-error check.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"

namespace crumple::io::testing {

inline const std::string kData = CRUMPLE_IO_TEST_DATA;

inline SceneSpec parse(const std::string& text) { return parseScene(text, "test.toml", kData); }

// Parsing `text` must throw InputError whose message starts with
// "test.toml:LINE: 'KEY': " and contains every fragment.
inline void expectError(const std::string& text, long line, const std::string& key,
                        std::initializer_list<std::string> fragments = {}) {
  try {
    parse(text);
    ADD_FAILURE() << "expected InputError for:\n" << text;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    const std::string prefix = "test.toml:" + std::to_string(line) + ": '" + key + "': ";
    EXPECT_EQ(msg.rfind(prefix, 0), 0u) << "message: " << msg << "\nexpected prefix: " << prefix;
    for (const std::string& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }
}

}  // namespace crumple::io::testing
