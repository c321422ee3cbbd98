// The small sets the hand-over tests run on, once per hand-over level: 4×4 subtiles per tile, three levels
// (32 … 512 points per tile) handed over onto the subtiles' level 0, or four (32 … 2,048) onto level 1 with
// a slack of 1 keyframe (×1.41 of density here).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "kdm/generator/bake.h"

namespace kdm::testing {

/// The recipe of the small set handing over onto its subtiles' level `level` (0; or 1, with slack), quickly
/// baked.
inline gen::BakeRecipe small_handover_recipe(std::uint32_t level) {
  gen::BakeRecipe r;
  r.levels = 3 + level, r.base_points = 32, r.sweeps = 20, r.keyframes_per_level = 4, r.glide_sweeps = 10;
  r.handover_zone = 1, r.handover_level = level, r.handover_slack = level ? 1 : 0;
  return r;
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
