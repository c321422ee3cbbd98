// Aggregation of the metrics over many point sets (docs/design.md §6): loading, the per-metric calls, pooling
// rules (NN distances pooled after per-set normalisation; the periodogram averaged over sets; density z
// pooled over all windows) and the text summary.
#include "kdm/analysis/report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "kdm/analysis/common.h"

namespace kdm::analysis {

namespace {

/// Whether every point's third coordinate is a whole number: a labelled file's class column, read as z
/// because the file has no header naming it.
bool whole_third_column(const tools::PointSet& set) {
  if (set.dim != 3) return false;
  for (std::size_t i = 2; i < set.coords.size(); i += 3)
    if (set.coords[i] != std::floor(set.coords[i])) return false;
  return true;
}

constexpr const char* kClassHeaderHint = "a class column needs the header line x,y,class";

/// RMS z of window counts above which a set is not uniform: Poisson points give 1, blue noise well under.
constexpr double kNonuniformRmsZ = 3;

/// Why the sets are not uniform, or "": a target density that varies by more than 10% over the square,
/// or windows of equal area whose counts vary far beyond Poisson (`uniform_rms_z`: their RMS z when the
/// density test already counted them, else NaN). The spectrum of such a set measures its density.
std::string nonuniform_reason(const std::vector<tools::PointSet>& sets, const AnalysisOptions& o,
                              const Sides& sides, double uniform_rms_z) {
  if (o.density) {
    double lo = HUGE_VAL, hi = 0;
    constexpr int kGrid = 64;
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        const double v = o.density((i + 0.5) / kGrid, (j + 0.5) / kGrid);
        lo = std::min(lo, v), hi = std::max(hi, v);
      }
    if (hi > 1.1 * lo) return "the target density is not constant";
  }
  double rms_z = uniform_rms_z;
  if (!std::isfinite(rms_z)) {
    DensityOptions dopt;
    dopt.min_expected = o.min_expected;
    dopt.bands = 1;
    dopt.sides = sides;
    double z2 = 0, windows = 0;
    for (const tools::PointSet& s : sets) {
      const DensityAccuracy d = density_accuracy(
          s.coords, 2, [](double, double) { return 1.0; }, dopt);
      z2 += d.rms_z * d.rms_z * double(d.windows), windows += double(d.windows);
    }
    rms_z = windows > 0 ? std::sqrt(z2 / windows) : 0;
  }
  if (rms_z > kNonuniformRmsZ) {
    char why[128];
    std::snprintf(why, sizeof why,
                  "window counts vary far beyond Poisson: RMS z %.1f against a uniform density", rms_z);
    return why;
  }
  return "";
}

}  // namespace

std::vector<tools::PointSet> load_point_sets(const std::vector<std::string>& paths,
                                             std::vector<std::string>* warnings) {
  if (paths.empty()) throw InvalidInput("no point files given");
  std::vector<tools::PointSet> all;
  for (const std::string& path : paths) {
    std::vector<tools::PointSet> sets;
    std::string error;
    if (!tools::read_point_sets(path, sets, error)) throw InvalidInput(error);
    bool whole = true;
    for (std::size_t k = 0; k < sets.size(); ++k) {
      if (!all.empty() && sets[k].dim != all.front().dim)
        throw InvalidInput(path + ": " + std::to_string(sets[k].dim) + "D points after " +
                           std::to_string(all.front().dim) + "D ones");
      // Classes are measured over every set pooled: one set without them leaves them meaningless.
      if (!all.empty() && sets[k].classes.empty() != all.front().classes.empty())
        throw InvalidInput(path + " (set " + std::to_string(k + 1) + "): " +
                           (sets[k].classes.empty() ? "points without classes after labelled ones"
                                                    : "labelled points after points without classes") +
                           ": pool labelled files only with labelled ones");
      whole = whole && whole_third_column(sets[k]);
      try {
        validate_points(sets[k].coords, sets[k].dim);
      } catch (const InvalidInput& e) {
        const bool hint = whole_third_column(sets[k]);
        // Finite coordinates past [0, 1] are most likely world units, as kdm query writes .csv.
        const bool finite = std::all_of(sets[k].coords.begin(), sets[k].coords.end(),
                                        [](double v) { return std::isfinite(v); });
        throw InvalidInput(
            path + " (set " + std::to_string(k + 1) + "): " + e.what() +
            (hint     ? std::string(" (its third column holds whole numbers only: ") + kClassHeaderHint + ")"
             : finite ? std::string(" (kdm query writes world units to .csv: give it --normalised, "
                                    "or write .txt)")
                      : ""));
      }
      all.push_back(std::move(sets[k]));
    }
    if (whole && warnings)
      warnings->push_back(path +
                          ": 3D points whose z is 0 or 1 in every one: if the third column is a class, " +
                          kClassHeaderHint);
  }
  return all;
}

AnalysisReport analyze(const std::vector<tools::PointSet>& sets, const AnalysisOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (sets.empty()) throw InvalidInput("no point sets to analyse");
  AnalysisReport r;
  r.dim = sets.front().dim;
  r.torus = o.torus;
  r.sets = sets.size();
  r.points_min = sets.front().size();
  double total = 0;
  for (const tools::PointSet& s : sets) {
    if (s.dim != r.dim) throw InvalidInput("point sets mix dimensions");
    if (s.size() < 2) throw InvalidInput("every point set needs at least 2 points");
    r.points_min = std::min(r.points_min, s.size());
    r.points_max = std::max(r.points_max, s.size());
    total += static_cast<double>(s.size());
  }
  r.points_mean = total / static_cast<double>(sets.size());
  r.sides = unit_measure_sides(o.extent, r.dim);
  const Sides& sides = r.sides;
  if (o.tile_size > 0) tiles_per_axis(o.tile_size);  // validate options before the expensive parts
  if (o.tile_size > 0 && !unit_sides(sides))
    throw InvalidInput(
        "tiling diagnostics take square tiles of the unit square: leave out the tile size for "
        "a set drawn in a rectangle");

  const auto checkpoint = [&] {
    if (o.checkpoint) o.checkpoint();
  };
  std::vector<double> pooled, seam, interior;
  for (const tools::PointSet& s : sets) {
    checkpoint();
    const NearestNeighbours nn = nearest_neighbours(s.coords, s.dim, o.torus, o.threads, sides);
    const double spacing = reference_spacing(s.dim, s.size());
    double lo = nn.distance.front();
    for (double d : nn.distance) {
      pooled.push_back(d / spacing);
      lo = std::min(lo, d);
      r.coincident += d == 0;
    }
    r.dmin_per_set.push_back(lo / spacing);
    if (o.tile_size > 0) split_by_seam(s.coords, s.dim, nn, o.tile_size, seam, interior);
    if (o.tile_size > 0 && s.dim == 2) add_edge_bands(s.coords, s.dim, o.tile_size, r.edges);
  }
  r.nn = summarise_nn(pooled, 1.0);
  r.dmin_mean = 0;
  for (double d : r.dmin_per_set) r.dmin_mean += d / static_cast<double>(r.dmin_per_set.size());

  checkpoint();
  // The other measures pool sets of any sizes; the spectrum's frequencies are in units of each set's √n.
  if (o.spectrum && r.dim == 2 && double(r.points_max) > 1.1 * double(r.points_min)) {
    r.spectrum_skipped = "sets of " + std::to_string(r.points_min) + " to " + std::to_string(r.points_max) +
                         " points (more than 10% apart) have no common frequency axis: analyse them apart";
  } else if (o.spectrum && r.dim == 2) {
    r.spectrum = average_periodogram(sets, o.fmax, o.threads, sides);
    r.spectrum_stats = spectrum_stats(r.spectrum);
    r.has_spectrum = true;
  } else if (o.spectrum) {
    r.spectrum_skipped = "2D only (3D sets get nearest neighbours, g(r) and the energy)";
  }
  checkpoint();
  r.gr = pair_correlation(sets, o.torus, o.gr_rmax, o.gr_bins, o.threads, sides);
  checkpoint();
  if (r.dim == 2 && r.points_min < 3)
    r.empty_circles_skipped = "a set of fewer than 3 points has no triangle";
  if (r.dim != 2) r.empty_circles_skipped = "2D only (no empty spheres)";
  if (r.dim == 2 && r.points_min >= 3) {
    EmptyCircleOptions eo;
    eo.torus = o.torus;
    eo.density = o.density;
    eo.tile_size = o.tile_size;
    eo.min_relative_density = o.holes_min_density;
    eo.threads = o.threads;
    eo.sides = sides;
    try {  // the other measures stand without them
      r.empty_circles = empty_circles(sets, eo);
      r.has_empty_circles = r.empty_circles.triangles > 0;
      if (!r.has_empty_circles)  // zeros would read as a set without holes
        r.empty_circles_skipped =
            o.torus     ? "no circle was judged: the density is too low at every one (--holes-min-density)"
            : o.density ? "no circle was judged: none lies two spacings inside the window where the density "
                          "is high enough (too few points for a box, or --holes-min-density)"
                        : "no circle was judged: none lies two spacings inside the window (too few points "
                          "for a box)";
    } catch (const DegenerateSet& e) {
      r.empty_circles_skipped = e.what();
    }
  }

  if (o.density && r.dim == 2) {
    DensityOptions dopt;
    dopt.min_expected = o.min_expected;
    dopt.bands = o.density_bands;
    dopt.sides = sides;
    double z2 = 0, mu_sum = 0, count_sum = 0;  // pooled over all windows of all sets
    for (const tools::PointSet& s : sets) {
      checkpoint();
      const DensityAccuracy d = density_accuracy(s.coords, s.dim, o.density, dopt);
      const double w = static_cast<double>(d.windows);
      z2 += d.rms_z * d.rms_z * w;
      mu_sum += d.mean_expected * w;
      count_sum += (1.0 + d.bias) * d.mean_expected * w;  // Σcount of the set's windows
      r.density.points += d.points;
      r.density.windows += d.windows;
      r.density.zero_density += d.zero_density;
      r.density.max_abs_z = std::max(r.density.max_abs_z, d.max_abs_z);
      if (r.density.bands.empty())
        r.density.bands = d.bands;  // same density and raster: same bands
      else
        for (std::size_t b = 0; b < d.bands.size(); ++b) {
          r.density.bands[b].expected += d.bands[b].expected;
          r.density.bands[b].count += d.bands[b].count;
        }
    }
    if (r.density.windows) {
      const double w = static_cast<double>(r.density.windows);
      r.density.rms_z = std::sqrt(z2 / w);
      r.density.mean_expected = mu_sum / w;
      r.density.bias = (count_sum - mu_sum) / mu_sum;
    }
    r.has_density = true;
    r.density_min_expected = o.min_expected;
  }

  if (r.has_spectrum) {
    checkpoint();
    // The density test's windows are those of a uniform density when its target is constant.
    const double rms_z = r.has_density && r.density.windows > 0 ? r.density.rms_z : std::nan("");
    r.spectrum_nonuniform = nonuniform_reason(sets, o, sides, rms_z);
  }

  if (o.tile_size > 0) {
    r.has_tiling = true;
    r.tile_size = o.tile_size;
    r.seams.seam = summarise_nn(seam, 1.0);
    r.seams.interior = summarise_nn(interior, 1.0);
    r.seams.ks = ks_two_sample(seam, interior);
    if (r.has_spectrum)
      r.periodicity = periodicity_ratio(r.spectrum, r.spectrum_stats, o.tile_size);
    else
      r.periodicity.ratio = r.periodicity.lattice_ratio = std::nan("");
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

/// Appends printf-style text to `s` (a line of the summary; the format checked as printf's).
__attribute__((format(printf, 2, 3))) void append(std::string& s, const char* fmt, ...) {
  char line[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  s += line;
}

}  // namespace

std::string format_summary(const AnalysisReport& r) {
  std::string s;
  append(s, "%zu set(s) of %zu", r.sets, r.points_min);
  if (r.points_max != r.points_min) append(s, "..%zu", r.points_max);
  // The default (torus) reads a bounded set as wrapping around: say which distances, and how to get the
  // other.
  append(s, " %dD points, %s\n", r.dim,
         r.torus ? "torus distances (the set wraps around; --box for a bounded set)"
                 : "box distances (a bounded set; --torus for one that wraps around)");
  if (!unit_sides(r.sides)) {  // the unit square's summary stays as it was
    if (r.dim == 2)
      append(s,
             "domain             %.4g × %.4g rectangle (aspect %.4g, unit area): distances in its lengths\n",
             r.sides[0], r.sides[1], r.sides[0] / r.sides[1]);
    else
      append(s, "domain             %.4g × %.4g × %.4g box (unit volume): distances in its lengths\n",
             r.sides[0], r.sides[1], r.sides[2]);
  }
  append(s, "nearest neighbour  δmin %.3f (mean over sets %.3f)  δavg %.3f  NN1%% %.3f  (units of %s)\n",
         r.nn.dmin, r.dmin_mean, r.nn.davg, r.nn.nn1, r.dim == 2 ? "d_hex" : "FCC spacing");
  if (r.coincident > 0)
    append(s, "                   warning: %zu points lie on another (distance 0): holes and g(r) mislead\n",
           r.coincident);
  if (!r.spectrum_skipped.empty()) append(s, "spectrum           skipped: %s\n", r.spectrum_skipped.c_str());
  if (r.has_spectrum) {
    const SpectrumStats& st = r.spectrum_stats;
    append(s, "spectrum (f ≤ %.2f, %d set(s))  ", r.spectrum.fmax, r.spectrum.sets);
    // lowP's band (below half the points' mean frequency) holds no frequency for sets of 4 points or fewer.
    if (std::isfinite(st.low_p))
      append(s, "lowP %.4f", st.low_p);
    else
      append(s, "lowP n/a (too few points)");
    append(s, "  peak %.2f at f=%.3f  ν_eff %.3f", st.peak, st.peak_f, st.nu_eff);
    // Anisotropy's rings lie in 0.5 < f < 2.5: none below --fmax 0.5.
    if (std::isfinite(st.anisotropy_db))
      append(s, "  anisotropy %.1f dB\n", st.anisotropy_db);
    else
      append(s, "  anisotropy n/a (no ring above f = 0.5)\n");
    if (!r.spectrum_nonuniform.empty())
      append(s,
             "                   note: not a uniform set (%s): the spectrum measures the density's own "
             "variation, not blue-noise quality\n",
             r.spectrum_nonuniform.c_str());
  }
  double gmax = 0, rpeak = 0;
  for (std::size_t b = 0; b < r.gr.g.size(); ++b)
    if (r.gr.g[b] > gmax) {
      gmax = r.gr.g[b];
      rpeak = r.gr.r[b];
    }
  if (gmax > 0)
    append(s, "pair correlation   g peak %.2f at r=%.2f (r ≤ %.1f)\n", gmax, rpeak, r.gr.r_max);
  else  // a few points far apart: no pair within reach
    append(s, "pair correlation   g peak n/a (no pair within r ≤ %.1f)\n", r.gr.r_max);
  if (!r.empty_circles_skipped.empty())
    append(s, "empty circles      skipped: %s\n", r.empty_circles_skipped.c_str());
  if (r.has_empty_circles) {
    const EmptyCircles& e = r.empty_circles;
    append(
        s,
        "empty circles      largest %.3f  99.9%% %.3f  > 0.85: %zu (%.1f per 10^5 points)  > 1.0: %zu (%.1f) "
        " "
        "(Delaunay, local d_hex%s)\n",
        e.largest, e.p999, e.over_085, e.over_085_per_1e5(), e.over_100, e.over_100_per_1e5(),
        r.torus ? "" : ", away from the border");
    if (e.triangles > 0) {
      char where[64] = "";
      if (r.sets > 1) std::snprintf(where, sizeof where, " of set %zu", e.largest_set + 1);
      append(s, "                   the largest centred at (%.4f, %.4f)%s\n", e.largest_x, e.largest_y,
             where);
    }
    if (r.has_tiling && e.over_085 > 0)
      append(s,
             "                   of those > 0.85, %.0f%% within one spacing of a tile edge (%.0f%% of all "
             "circles)\n",
             100.0 * e.over_085_near_edge / e.over_085, 100 * e.near_edge_share);
  }
  if (r.has_density)
    append(
        s,
        "density            %zu windows (μ≈%.1f)  RMS z %.3f  max|z| %.2f  bias %+.4f  in zero density %zu\n",
        r.density.windows, r.density.mean_expected, r.density.rms_z, r.density.max_abs_z, r.density.bias,
        r.density.zero_density);
  if (r.has_density && r.density.mean_expected < r.density_min_expected)
    append(s,
           "                   warning: no window expects %g points (--min-expected; a set has %zu): one "
           "window a set, whose z says nothing\n",
           r.density_min_expected, r.points_min);
  if (r.has_density && r.density.bands.size() > 1) {
    append(s, "density bands      ρ/ρmax from        expected      points  count/target   ±1σ (Poisson)\n");
    for (const DensityBand& b : r.density.bands)
      if (b.expected < 1)  // a ratio to less than a point says nothing (a picture's faint fringe)
        append(s, "                   %.3g–%-10.3g %10.1f  %10.0f  %12s  %8s\n", b.lo, b.hi, b.expected,
               b.count, "-", "-");
      else
        append(s, "                   %.3g–%-10.3g %10.1f  %10.0f  %12.4f  %8.4f\n", b.lo, b.hi, b.expected,
               b.count, 1 + b.bias(), 1 / std::sqrt(b.expected));
  }
  if (r.has_tiling) {
    append(
        s,
        "tiling (s=%g)      periodicity ratio %.2f over %zu frequencies; lattice power ratio %.2f (up to 2 "
        "cycles per tile, against their neighbours)\n",
        r.tile_size, r.periodicity.ratio, r.periodicity.frequencies, r.periodicity.lattice_ratio);
    append(s, "  seams   %6zu links  δmin %.3f  δavg %.3f  NN1%% %.3f\n", r.seams.seam.count,
           r.seams.seam.dmin, r.seams.seam.davg, r.seams.seam.nn1);
    append(s, "  inside  %6zu links  δmin %.3f  δavg %.3f  NN1%% %.3f   KS D %.4f  p %.3g\n",
           r.seams.interior.count, r.seams.interior.dmin, r.seams.interior.davg, r.seams.interior.nn1,
           r.seams.ks.statistic, r.seams.ks.p_value);
    if (r.dim == 2) {
      append(s, "  edges   density within one spacing of tile edges %+.2f%% of the mean; by quarter spacing:",
             100 * (r.edges.first_spacing_ratio() - 1));
      for (int b = 0; b < EdgeBands::kBands; ++b) append(s, " %+.1f", 100 * (r.edges.ratio(b) - 1));
      append(s, "%%\n");
    }
  }
  if (r.has_energy)
    append(s, "KDM energy         E/n %.4f (finest grid of the model for this count and density)\n",
           r.energy_per_point);
  append(s, "analysis time %.2f s\n", r.seconds);
  return s;
}

}  // namespace kdm::analysis
