// The small sets the hand-over tests run on, once per hand-over level: 4×4 subtiles per tile, three levels
// (32 … 512 points per tile) handed over onto the subtiles' level 0, or four (32 … 2,048) onto level 1 with
// a slack of 1 keyframe (×1.41 of density here). Their recipes are tests/data/handover{,_slack}.recipe.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "kdm/generator/bake.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm::testing {

/// The recipe file of the small set handing over onto its subtiles' level `level` (0; or 1, with slack).
inline std::string small_handover_name(std::uint32_t level) {
  return level ? "handover_slack" : "handover";
}

/// That set's recipe, tests/data/<name>.recipe: the format's readers are tested on the same sets.
inline gen::BakeRecipe small_handover_recipe(std::uint32_t level) {
  std::ifstream in(std::string(KDM_TEST_DATA_DIR) + "/" + small_handover_name(level) + ".recipe");
  std::stringstream text;
  text << in.rdbuf();
  return gen::BakeRecipe::parse(text.str());
}

/// That set: the file the fixture handover_sets baked into $KDM_HANDOVER_SETS (ctest sets it), else baked
/// here (seconds; ten times that under the sanitizers, once per test process).
inline TilesetData small_handover_set(std::uint32_t level) {
  TilesetData set;
  if (const char* dir = std::getenv("KDM_HANDOVER_SETS")) {
    const std::string path = std::string(dir) + "/" + small_handover_name(level) + ".kdmt";
    std::string detail;
    EXPECT_EQ(load_tileset(path, set, &detail), Status::kOk) << path << ": " << detail;
  } else {
    set = gen::bake_tileset(small_handover_recipe(level), 2);
  }
  return set;
}

/// A suite whose tests run once per hand-over level (the parameter, 0 or 1) on make(level), made once per
/// level and shared by the suite's tests; set() is the running test's.
template <class Set, Set (*make)(std::uint32_t)>
class HandoverLevelTest : public ::testing::TestWithParam<std::uint32_t> {
 public:
  static const Set& set() { return *current_; }

 protected:
  void SetUp() override {
    if (GetParam() == 0) {
      static const Set level0 = make(0);
      current_ = &level0;
    } else {
      static const Set level1 = make(1);
      current_ = &level1;
    }
  }

 private:
  static inline const Set* current_ = nullptr;
};

/// The name of a test's instance: OntoLevel0 or OntoLevel1WithSlack.
inline std::string handover_level_name(const ::testing::TestParamInfo<std::uint32_t>& info) {
  return "OntoLevel" + std::to_string(info.param) + (info.param ? "WithSlack" : "");
}

}  // namespace kdm::testing
