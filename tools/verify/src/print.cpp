// The generator test's report as text tables (kdm verify).
#include <cmath>
#include <string>
#include <vector>

#include "kdm/verify/verify.h"

namespace kdm::verify {
namespace {

// The check whose name starts with `prefix` that failed, else the first with that prefix (or null).
const Check* find(const std::vector<Check>& checks, const std::string& prefix) {
  const Check* found = nullptr;
  for (const Check& c : checks)
    if (c.name.compare(0, prefix.size(), prefix) == 0) {
      if (!c.passed()) return &c;
      if (!found) found = &c;
    }
  return found;
}

// `value` in a column of `width`, marked '!' when the check named `prefix` failed, '-' when NaN.
std::string cell(double value, const char* format, const std::vector<Check>& checks,
                 const std::string& prefix, int width) {
  char text[48];
  if (std::isnan(value))
    std::snprintf(text, sizeof text, "-");
  else
    std::snprintf(text, sizeof text, format, value);
  std::string s = text;
  const Check* c = find(checks, prefix);
  if (c && !c->passed()) s += "!";
  while (int(s.size()) < width) s.insert(s.begin(), ' ');
  return s;
}

// The largest hole and the holes above 0.85 d_hex per 10^5 points, in two columns ("-" where not measured).
std::string hole_cells(const Holes& holes, const std::vector<Check>& checks) {
  const double nan = std::nan("");
  return cell(holes.measured ? holes.largest : nan, "%.3f", checks, "largest hole", 6) + " " +
         cell(holes.measured ? holes.per_1e5() : nan, "%.1f", checks, "holes per", 7);
}

void print_failures(const std::vector<Check>& checks, const std::string& what, std::FILE* out) {
  for (const Check& c : checks)
    if (!c.passed())
      std::fprintf(out, "  FAIL %s: %s %.4g, bar %s %.4g\n", what.c_str(), c.name.c_str(), c.value,
                   c.at_most ? "<=" : ">=", c.bar);
}

}  // namespace

void print_report(const Report& report, std::FILE* out, bool tables) {
  std::size_t checks = 0;
  bool tile_checks = false;
  for (const TileResult& t : report.tiles)
    tile_checks = tile_checks || !t.checks.empty(), checks += t.checks.size();
  for (const DensityResult& d : report.densities) checks += d.checks.size();
  for (const KeyframeResult& k : report.keyframes) checks += k.checks.size();
  for (const LevelReference& level : report.levels) {
    if (!tile_checks || !tables) break;
    std::fprintf(
        out,
        "\nlevel %u, %u points per tile (each tile judged on a %g×%g torus of it and the tiles its corners "
        "fit: 'torus' points); "
        "reference: full-sampler runs on that torus: E/n %.4f  "
        "δavg %.4f  NN1%% %.3f  lowP %.4f (largest %.4f); freed for 15 sweeps: drop %s, drift %s\n",
        level.level, level.points_per_tile, level.side, level.side, level.energy, level.davg, level.nn1,
        level.low_p, level.low_p_max, cell(level.control_drop, "%.4f", {}, "", 0).c_str(),
        cell(level.control_drift, "%.3f", {}, "", 0).c_str());  // "-" where not measured (--no-direct)
    std::fprintf(out, "%5s %11s %7s %8s %8s %7s %8s %5s %8s %7s  %s\n", "tile", "sw se ne nw", "torus", "E/n",
                 "δavg", "NN1%", "lowP", "RAPS", "drop", "drift", "result");
    for (const TileResult& t : report.tiles) {
      if (t.level != level.level) continue;
      const Check* raps = find(t.checks, "|ΔRAPS|");
      std::fprintf(
          out, "%5zu %2u %2u %2u %2u %7zu %s %s %s %s %5s %s %s  %s\n", t.tile, t.colours[0], t.colours[1],
          t.colours[2], t.colours[3], t.points, cell(t.energy, "%.4f", t.checks, "E/n", 8).c_str(),
          cell(t.davg, "%.4f", t.checks, "δavg", 8).c_str(), cell(t.nn1, "%.3f", t.checks, "NN1%", 7).c_str(),
          cell(t.low_p, "%.4f", t.checks, "lowP", 8).c_str(), raps ? (raps->passed() ? "ok" : "FAIL!") : "-",
          cell(t.drop, "%.4f", t.checks, "energy drop", 8).c_str(),
          cell(t.drift, "%.3f", t.checks, "drift", 7).c_str(), t.passed() ? "pass" : "FAIL");
    }
  }
  if (!report.densities.empty() && tables) {
    std::fprintf(out, "\nseams and in-between densities, over every tile's torus\n");
    std::fprintf(out, "%11s %7s %7s %10s %10s %8s %9s %10s %8s %9s %6s %7s  %s\n", "points/tile", "kind",
                 "δavg", "edge/other", "edge links", "KS D+", "p", "worst lowP", "closest", "edge band",
                 "hole", "/1e5", "result");
    for (const DensityResult& d : report.densities) {
      std::fprintf(out, "%11.1f %7s %7.4f %s %10zu %s %9.2g %s %s %s %s  %s\n", d.points_per_tile,
                   d.complete_level ? "level" : "between", d.davg,
                   cell(d.worst_edge_ratio, "%.3f", d.checks, "edge δmin", 10).c_str(), d.edge_links,
                   cell(d.ks_d_plus, "%.4f", d.checks, "edge vs midline", 8).c_str(), d.ks_p,
                   cell(d.worst_low_p, "%.4f", d.checks, "lowP", 10).c_str(),
                   cell(d.closest_pair, "%.3f", d.checks, "closest pair", 8).c_str(),
                   cell(100 * (d.edge_band - 1), "%+.1f%%", d.checks, "|edge band", 9).c_str(),
                   hole_cells(d.holes, d.checks).c_str(), d.passed() ? "pass" : "FAIL");
    }
  }
  if (!report.keyframes.empty() && tables) {
    std::fprintf(
        out,
        "\nglide track (smooth mode), over every tile's torus; closest pair in d_hex; motion from the "
        "keyframe before, in mean nearest-neighbour distances\n");
    std::fprintf(out, "%11s %9s %7s %8s %11s %10s %6s %7s  %s\n", "points/tile", "kind", "δavg", "closest",
                 "motion mean", "motion p99", "hole", "/1e5", "result");
    for (const KeyframeResult& k : report.keyframes) {
      std::fprintf(out, "%11.1f %9s %7.4f %s %s %s %s  %s\n", k.points_per_tile,
                   k.handover   ? "hand-over"
                   : k.keyframe ? "keyframe"
                                : "half-way",
                   k.davg, cell(k.closest_pair, "%.3f", k.checks, "closest pair", 8).c_str(),
                   cell(k.motion_mean, "%.3f", k.checks, "motion mean", 11).c_str(),
                   cell(k.motion_p99, "%.3f", k.checks, "motion p99", 10).c_str(),
                   hole_cells(k.holes, k.checks).c_str(), k.passed() ? "pass" : "FAIL");
    }
  }
  if (tables) std::fprintf(out, "\n");
  for (const TileResult& t : report.tiles)
    print_failures(t.checks, "tile " + std::to_string(t.tile) + " level " + std::to_string(t.level), out);
  const auto per_tile = [](double v) {  // as the tables print it, so that a line finds its row
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", v);
    return std::string(text);
  };
  for (const DensityResult& d : report.densities)
    print_failures(d.checks, "at " + per_tile(d.points_per_tile) + " points per tile", out);
  for (const KeyframeResult& k : report.keyframes)
    print_failures(k.checks, "gliding at " + per_tile(k.points_per_tile) + " points per tile", out);
  const std::size_t failed = report.failed_checks();
  if (failed) {
    std::fprintf(out, "%zu of %zu checks failed\n", failed, checks);
    // At the coarsest levels one patch is most of a tile, and one drawn a little tight fails every tile
    // that shows it: a draw's luck more than the recipe's, which another seed usually changes.
    // The holes' bars are the caller's own (none by default): a set failing them needs no other seed.
    // So is a miss by more than a quarter of a bar of the design's: a damaged file or a broken baker,
    // not a draw (the draws measured in docs/design.md §5 miss by under 8%).
    const auto is_hole = [](const Check& c) { return c.name.find("hole") != std::string::npos; };
    const auto far = [&](const Check& c) {
      const double miss = c.at_most ? c.value - c.bar : c.bar - c.value;
      return !c.passed() && !is_hole(c) && !(miss <= 0.25 * std::abs(c.bar));
    };
    std::size_t far_misses = 0;
    const auto count_far = [&](const std::vector<Check>& checks) {
      for (const Check& c : checks) far_misses += far(c);
    };
    for (const TileResult& t : report.tiles) count_far(t.checks);
    for (const DensityResult& d : report.densities) count_far(d.checks);
    for (const KeyframeResult& k : report.keyframes) count_far(k.checks);
    const auto small = [&](const std::vector<Check>& checks, double points_per_tile) {
      for (const Check& c : checks)
        if (!c.passed() && is_hole(c)) return false;
      return std::sqrt(points_per_tile) < Bars{}.small_tile_spacings;
    };
    bool only_small = true;
    for (const TileResult& t : report.tiles)
      only_small = only_small && (t.passed() || small(t.checks, t.points / 4.0));
    for (const DensityResult& d : report.densities)
      only_small = only_small && (d.passed() || small(d.checks, d.points_per_tile));
    // A draw's luck fails a few rows of the glide track; most of it failing is the recipe's glide
    // (too few keyframes: 8 at 2 levels fail 14 of 17 rows, seeds 1-8 at the shipped 24 at most 4 of 49).
    std::size_t glide_failed = 0;
    for (const KeyframeResult& k : report.keyframes) {
      glide_failed += !k.passed();
      only_small = only_small && (k.passed() || small(k.checks, k.points_per_tile));
    }
    const std::size_t glide_rows = report.keyframes.size();
    if (glide_failed * 4 > glide_rows) {
      only_small = false;
      std::fprintf(out,
                   "the glide track fails at %zu of its %zu rows: its recipe, not a seed's draw (fewer "
                   "keyframes give each interval more motion; the shipped recipe's 24 per level pass)\n",
                   glide_failed, glide_rows);
    }
    if (far_misses)
      std::fprintf(out,
                   "%zu failed check(s) miss their bar by more than a quarter of it, more than a seed's draw "
                   "does: the file is damaged or its recipe gives poor tiles (docs/design.md §5)\n",
                   far_misses);
    else if (only_small)
      std::fprintf(out,
                   "every failure is at a density whose tiles are under %.0f point spacings wide, where a "
                   "patch or two make a tile: another seed usually passes (docs/design.md §5)\n",
                   Bars{}.small_tile_spacings);
  } else
    std::fprintf(out, "all %zu checks passed\n", checks);
}

}  // namespace kdm::verify
