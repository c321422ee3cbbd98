// Hand-written JSON output (RFC 8259 subset: no pretty printing beyond newlines between top-level keys)
// for metrics.json; field names follow docs/design.md §6 (dmin, davg, nn1, low_p, nu_eff, anisotropy_db,
// ...).
#include "kdm/analysis/json.h"

#include <cmath>
#include <cstdio>

namespace kdm::analysis {

namespace {

/// The length of the well-formed UTF-8 sequence at s[i] (RFC 3629: no overlong forms, no surrogates, at most
/// U+10FFFF), or 0.
std::size_t utf8_sequence(const std::string& s, std::size_t i) {
  const auto at = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
  const unsigned c = at(i);
  const std::size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
  if (n == 0 || c > 0xF4) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((at(i + k) & 0xC0) != 0x80) return 0;
  const unsigned second = at(i + 1);
  if ((c == 0xE0 && second < 0xA0) || (c == 0xED && second >= 0xA0) || (c == 0xF0 && second < 0x90) ||
      (c == 0xF4 && second >= 0x90))
    return 0;
  return n;
}

}  // namespace

std::string json_quote(const std::string& s) {
  std::string q = "\"";
  for (std::size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {  // JSON is UTF-8: a byte of no character (a Latin-1 file name) is written as \ufffd
      const std::size_t n = utf8_sequence(s, i);
      q += n ? s.substr(i, n) : "\\ufffd";
      i += n ? n - 1 : 0;
      continue;
    }
    switch (c) {
      case '"':
        q += "\\\"";
        break;
      case '\\':
        q += "\\\\";
        break;
      case '\n':
        q += "\\n";
        break;
      case '\r':
        q += "\\r";
        break;
      case '\t':
        q += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          q += buf;
        } else {
          q += static_cast<char>(c);
        }
    }
  }
  return q + "\"";
}

void JsonWriter::separator() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
}

JsonWriter& JsonWriter::begin_object() {
  separator();
  out_ += '{';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_object() {
  first_.pop_back();
  out_ += first_.empty() ? "\n}\n" : "}";
  return *this;
}
JsonWriter& JsonWriter::begin_array() {
  separator();
  out_ += '[';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_array() {
  first_.pop_back();
  out_ += ']';
  return *this;
}
JsonWriter& JsonWriter::key(const std::string& k) {
  separator();
  if (first_.size() == 1) out_ += "\n  ";
  out_ += json_quote(k) + ':';
  after_key_ = true;
  return *this;
}
JsonWriter& JsonWriter::value(double v) {
  separator();
  if (!std::isfinite(v)) {
    out_ += "null";
  } else {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    out_ += buf;
  }
  return *this;
}
JsonWriter& JsonWriter::value(long long v) {
  separator();
  out_ += std::to_string(v);
  return *this;
}
JsonWriter& JsonWriter::value(bool v) {
  separator();
  out_ += v ? "true" : "false";
  return *this;
}
JsonWriter& JsonWriter::value(const std::string& v) {
  separator();
  out_ += json_quote(v);
  return *this;
}
JsonWriter& JsonWriter::value(const std::vector<double>& v) {
  begin_array();
  for (double x : v) value(x);
  return end_array();
}

namespace {

void write_nn(JsonWriter& w, const NNStats& s) {
  w.begin_object();
  w.key("count").value(s.count).key("dmin").value(s.dmin).key("davg").value(s.davg).key("nn1").value(s.nn1);
  w.key("dmax").value(s.dmax).key("histogram_max").value(s.hist_max).key("histogram").begin_array();
  for (std::size_t c : s.histogram) w.value(c);
  w.end_array();
  // The last bin holds these too: every distance of histogram_max spacings or more.
  w.key("histogram_overflow").value(s.overflow).end_object();
}

}  // namespace

std::string metrics_json(const AnalysisReport& r, const std::vector<std::string>& inputs) {
  JsonWriter w;
  w.begin_object();
  w.key("inputs").begin_array();
  for (const std::string& s : inputs) w.value(s);
  w.end_array();
  w.key("dim").value(r.dim).key("domain").value(r.torus ? "torus" : "box");
  if (!unit_sides(r.sides))  // the unit square's document stays as it was
    w.key("sides").value(std::vector<double>(r.sides.begin(), r.sides.begin() + r.dim));
  w.key("sets").value(r.sets).key("points_min").value(r.points_min).key("points_max").value(r.points_max);
  w.key("points_mean").value(r.points_mean);
  w.key("spacing_unit").value(r.dim == 2 ? "d_hex = sqrt(2/(sqrt(3) n))" : "fcc = (sqrt(2)/n)^(1/3)");
  w.key("nearest_neighbour");
  write_nn(w, r.nn);
  w.key("dmin_mean_over_sets").value(r.dmin_mean).key("dmin_per_set").value(r.dmin_per_set);
  w.key("coincident_points").value(r.coincident);
  if (!r.spectrum_skipped.empty()) w.key("spectrum_skipped").value(r.spectrum_skipped);
  if (r.has_spectrum) {
    const SpectrumStats& st = r.spectrum_stats;
    w.key("spectrum").begin_object();
    w.key("fmax")
        .value(r.spectrum.fmax)
        .key("kmax")
        .value(r.spectrum.kmax)
        .key("sets")
        .value(r.spectrum.sets);
    w.key("low_p").value(st.low_p).key("peak").value(st.peak).key("peak_f").value(st.peak_f);
    w.key("nu_eff").value(st.nu_eff).key("anisotropy_db").value(st.anisotropy_db);
    w.key("raps_f").value(st.ring_f).key("raps").value(st.raps);
    w.key("anisotropy_db_by_ring").value(st.ring_anisotropy_db);
    if (!r.spectrum_nonuniform.empty()) w.key("nonuniform").value(r.spectrum_nonuniform);
    w.end_object();
  }
  w.key("pair_correlation").begin_object();
  w.key("r_max").value(r.gr.r_max).key("r").value(r.gr.r).key("g").value(r.gr.g).end_object();
  if (!r.empty_circles_skipped.empty()) w.key("empty_circles_skipped").value(r.empty_circles_skipped);
  if (r.has_empty_circles) {
    const EmptyCircles& e = r.empty_circles;
    w.key("empty_circles").begin_object();
    w.key("triangles").value(e.triangles).key("largest").value(e.largest).key("p999").value(e.p999);
    w.key("largest_set").value(e.largest_set).key("largest_x").value(e.largest_x);
    w.key("largest_y").value(e.largest_y);
    w.key("over_085").value(e.over_085).key("over_100").value(e.over_100);
    w.key("over_085_per_1e5").value(e.over_085_per_1e5()).key("over_100_per_1e5").value(e.over_100_per_1e5());
    if (r.has_tiling)
      w.key("over_085_near_tile_edge")
          .value(e.over_085_near_edge)
          .key("near_tile_edge_share")
          .value(e.near_edge_share);
    w.end_object();
  }
  if (r.has_density) {
    const DensityAccuracy& d = r.density;
    w.key("density").begin_object();
    w.key("windows").value(d.windows).key("mean_expected").value(d.mean_expected).key("rms_z").value(d.rms_z);
    w.key("max_abs_z")
        .value(d.max_abs_z)
        .key("bias")
        .value(d.bias)
        .key("zero_density_points")
        .value(d.zero_density)
        .key("min_expected")
        .value(r.density_min_expected);
    w.key("bands").begin_array();
    for (const DensityBand& b : d.bands) {
      w.begin_object().key("rho_lo").value(b.lo).key("rho_hi").value(b.hi).key("expected").value(b.expected);
      w.key("count").value(b.count).key("bias").value(b.bias()).end_object();
    }
    w.end_array();
    w.end_object();
  }
  if (r.has_tiling) {
    w.key("tiling").begin_object();
    w.key("tile_size").value(r.tile_size);
    w.key("periodicity_ratio")
        .value(r.periodicity.ratio)
        .key("lattice_frequencies")
        .value(r.periodicity.frequencies)
        .key("lattice_power_ratio")
        .value(r.periodicity.lattice_ratio)
        .key("lattice_power_frequencies")
        .value(r.periodicity.lattice_frequencies);
    w.key("seam");
    write_nn(w, r.seams.seam);
    w.key("interior");
    write_nn(w, r.seams.interior);
    w.key("ks_statistic").value(r.seams.ks.statistic).key("ks_p_value").value(r.seams.ks.p_value);
    if (r.dim == 2) {
      std::vector<double> ratios;
      for (int b = 0; b < EdgeBands::kBands; ++b) ratios.push_back(r.edges.ratio(b));
      w.key("edge_band_density_ratio")
          .value(r.edges.first_spacing_ratio())
          .key("edge_band_profile")
          .value(ratios);
    }
    w.end_object();
  }
  if (r.has_energy) w.key("energy_per_point").value(r.energy_per_point);
  w.key("seconds").value(r.seconds);
  w.end_object();
  return w.str();
}

}  // namespace kdm::analysis
