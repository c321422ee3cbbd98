// Tile-set baking; see kdm/generator/bake.h.
#include "kdm/generator/bake.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <map>
#include <sstream>
#include <thread>
#include <tuple>
#include <type_traits>
#include <vector>

#include "bake/close_pairs.h"
#include "bake/corner_layout.h"
#include "bake/handover.h"
#include "bake/hole_finder.h"
#include "bake/keyframes.h"
#include "bake/progressive_order.h"
#include "bake/run_stages.h"
#include "bake/spacing_guard.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/check.h"
#include "kdm/runtime/version.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

// Void-and-cluster filter width in units of the current point spacing (progressive_order narrows it as
// points are added): half a spacing leaves the least low-frequency power between levels (docs/design.md §3).
constexpr double kFilterWidth = 0.5;

// The coarsest level's sweeps in the versions that baked the first tile sets (SamplerOptions's default was
// then 60): a recipe must bake the same tiles in every kdm version.
constexpr int kFirstCoarsestSweeps = 60;

// With the hard core on (BakeRecipe::min_distance), new points lying deeper than this many point spacings
// (of their level) inside a region of an earlier patch kind are dropped: such a point has other neighbours
// in every tile, and the margin between levels (corner_layout.h) must still separate it from the next
// level's patches, which are sampled without it.
constexpr double kMaxSlip = 0.1;

/// The shortest text that reads back as the same double: "band 0.35", not 0.34999999999999998.
std::string shortest(double v) {
  char text[32];
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

/// `text` for a message: bytes outside printable ASCII as \xNN (a key or value with an invisible byte in it
/// would print as if it were right), and at most 40 bytes of it.
std::string printable(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02X", c);
    out += c >= 0x20 && c < 0x7F ? std::string(1, char(c)) : std::string(hex);
  }
  return text.size() > 40 ? out + "..." : out;
}

/// How a key's value is checked against its [lo, hi].
enum class Range { kWhole, kWithin, kOpen, kOffOrWithin };

/// A numeric recipe key: its range, and its field read and written as a double (exact for every field).
struct KeyRule {
  const char* key;
  Range range;
  double lo, hi;
  double (*get)(const BakeRecipe&);
  void (*set)(BakeRecipe&, double);
};

template <auto Field>
double get_field(const BakeRecipe& r) {
  return static_cast<double>(r.*Field);
}
template <auto Field>
void set_field(BakeRecipe& r, double v) {
  using T = std::remove_reference_t<decltype(r.*Field)>;
  r.*Field = static_cast<T>(v);
}
template <auto Field>
constexpr KeyRule rule(const char* key, Range range, double lo, double hi) {
  return {key, range, lo, hi, &get_field<Field>, &set_field<Field>};
}

// Every key but `seed` (any 64-bit value, read exactly, not through a double), with its range: parse checks
// the text's values against them, validate a recipe's fields.
const KeyRule kKeyRules[] = {
    rule<&BakeRecipe::colours>("colours", Range::kWhole, 1, kMaxTileColours),
    rule<&BakeRecipe::levels>("levels", Range::kWhole, 1, 10),
    rule<&BakeRecipe::base_points>("base_points", Range::kWhole, 1, 1 << 16),
    rule<&BakeRecipe::sweeps>("sweeps", Range::kWhole, 1, 10000),
    rule<&BakeRecipe::band>("band", Range::kOpen, 0, 0.5),
    rule<&BakeRecipe::erosion>("erosion", Range::kWithin, 0, 8),
    rule<&BakeRecipe::edge_gap>("edge_gap", Range::kWithin, 0.5, 4),
    rule<&BakeRecipe::rank_context>("rank_context", Range::kWhole, 0, 2),
    rule<&BakeRecipe::min_distance>("min_distance", Range::kWithin, 0, 0.7),
    rule<&BakeRecipe::separation>("separation", Range::kWithin, 0, 0.7),
    rule<&BakeRecipe::separation_push>("separation_push", Range::kWithin, 0, 0.9),
    rule<&BakeRecipe::split_shared>("split_shared", Range::kWhole, 0, 1),
    rule<&BakeRecipe::separation_fill>("separation_fill", Range::kWhole, 0, 1),
    rule<&BakeRecipe::separation_per_level>("separation_per_level", Range::kWhole, 0, 1),
    rule<&BakeRecipe::fill_holes>("fill_holes", Range::kOffOrWithin, 0.5, 2),
    rule<&BakeRecipe::glide_separation>("glide_separation", Range::kWithin, 0, 0.7),
    rule<&BakeRecipe::keyframes_per_level>("keyframes", Range::kWhole, 0, 32),
    rule<&BakeRecipe::handover_zone>("handover_zone", Range::kWhole, 0, 127),
    rule<&BakeRecipe::handover_level>("handover_level", Range::kWhole, 0, 7),
    rule<&BakeRecipe::handover_slack>("handover_slack", Range::kWhole, 0, kMaxHandoverSlack),
    rule<&BakeRecipe::glide_consensus>("glide_consensus", Range::kWhole, 0, 1 << 22),
    rule<&BakeRecipe::glide_corner_consensus>("glide_corner_consensus", Range::kWhole, 0, 1 << 22),
    rule<&BakeRecipe::glide_late>("glide_late", Range::kWithin, 0, 0.95),
    rule<&BakeRecipe::glide_sweeps>("glide_sweeps", Range::kWhole, 1, 1000),
    rule<&BakeRecipe::temperature>("temperature", Range::kWithin, 0, kMaxTemperature),
};

const KeyRule* find_rule(const std::string& key) {
  for (const KeyRule& k : kKeyRules)
    if (key == k.key) return &k;
  return nullptr;
}

/// Why `v` (as the recipe wrote it: `shown`) is no value for `k`'s key, or "" when it is one.
std::string range_error(const KeyRule& k, double v, const std::string& shown) {
  const std::string key = k.key, got = ", got '" + printable(shown) + "'";
  switch (k.range) {
    case Range::kWhole:
      if (v != std::floor(v) || v < k.lo || v > k.hi)
        return key + " must be a whole number in [" + std::to_string(std::int64_t(k.lo)) + ", " +
               std::to_string(std::int64_t(k.hi)) + "]" + got;
      break;
    case Range::kWithin:
      if (!(v >= k.lo && v <= k.hi))
        return key + " must be in [" + shortest(k.lo) + ", " + shortest(k.hi) + "]" + got;
      break;
    case Range::kOpen:
      if (!(v > k.lo && v < k.hi))
        return key + " must be in (" + shortest(k.lo) + ", " + shortest(k.hi) + ")" + got;
      break;
    case Range::kOffOrWithin:
      if (v != 0 && !(v >= k.lo && v <= k.hi))
        return key + " must be 0 (off) or in [" + shortest(k.lo) + ", " + shortest(k.hi) + "]" + got;
      break;
  }
  return "";
}

/// The lines of recipe text: a line ends at LF, CR LF or a lone CR (a file saved with classic Mac line
/// ends would otherwise be one long line).
std::vector<std::string> text_lines(const std::string& text) {
  std::vector<std::string> lines(1);
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n' || text[i] == '\r') {
      if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      lines.emplace_back();
    } else {
      lines.back() += text[i];
    }
  }
  if (lines.back().empty()) lines.pop_back();
  return lines;
}

/// A line's words, split at ASCII blanks, after its comment.
std::vector<std::string> words_of(const std::string& line) {
  std::istringstream fields(line.substr(0, line.find('#')));
  std::vector<std::string> words;
  for (std::string word; fields >> word;) words.push_back(word);
  return words;
}

/// The first Unicode space (no-break, em, ideographic, ...) in `line` as its UTF-8 bytes, e.g. "C2 A0", or
/// "": text pasted from a document carries them, and they split nothing (a key and value would be one word).
std::string non_ascii_space(const std::string& line) {
  static const char* const kSpaces[] = {"\xC2\xA0",     "\xE1\x9A\x80", "\xE2\x80\xAF",
                                        "\xE2\x81\x9F", "\xE3\x80\x80", "\xEF\xBB\xBF"};
  std::size_t at = std::string::npos, length = 0;
  const auto found = [&](std::size_t pos, std::size_t bytes) {
    if (pos < at) at = pos, length = bytes;
  };
  for (const char* space : kSpaces) found(line.find(space), std::strlen(space));
  for (unsigned c = 0x80; c <= 0x8A; ++c)  // U+2000..U+200A
    found(line.find(std::string("\xE2\x80") + static_cast<char>(c)), 3);
  if (at == std::string::npos) return "";
  std::string bytes;
  for (std::size_t i = 0; i < length; ++i) {
    char hex[4];
    std::snprintf(hex, sizeof hex, "%02X", static_cast<unsigned char>(line[at + i]));
    bytes += (i ? " " : "") + std::string(hex);
  }
  return bytes;
}

/// Why a line that gives something is not one 'key value' pair, or "" when it is.
std::string layout_error(const std::string& line, const std::vector<std::string>& words) {
  const std::string code = line.substr(0, line.find('#'));
  if (const std::string space = non_ascii_space(code); !space.empty())
    return "a non-ASCII space (bytes " + space + ") is not a blank here: write the line with ASCII spaces";
  if (code.find('=') != std::string::npos) {
    std::string spaced = code;
    std::replace(spaced.begin(), spaced.end(), '=', ' ');
    const std::vector<std::string> parts = words_of(spaced);
    return "'=' is not used: write '" +
           (parts.size() == 2 ? printable(parts[0]) + " " + printable(parts[1]) : std::string("key value")) +
           "'";
  }
  if (words.size() == 1) return "'" + printable(words[0]) + "' has no value: expected 'key value'";
  if (words.size() > 2)
    return std::to_string(words.size()) + " words: expected 'key value' (a comment starts with '#')";
  return "";
}

/// The checks of a recipe's keys together (in the order a reader meets them). `lines` holds the line that
/// gave each key when the recipe comes from text (errors then name the line of the key at fault), or is
/// null for a recipe made in code, where a key counts as given when it differs from its default.
void check_together(const BakeRecipe& r, const std::map<std::string, int>* lines) {
  static const BakeRecipe kDefaults;
  const auto given = [&](const char* key) {
    if (lines) return lines->count(key) > 0;
    const KeyRule* k = find_rule(key);
    return k->get(r) != k->get(kDefaults);
  };
  const auto at = [&](const char* key) {
    if (lines)
      if (const auto it = lines->find(key); it != lines->end())
        return "recipe line " + std::to_string(it->second) + ": ";
    return std::string("recipe: ");
  };
  if (r.top_level_points() > (1u << 22)) {  // both keys' doing: named together where both are given
    std::string where = at(given("base_points") && !given("levels") ? "base_points" : "levels");
    if (lines && lines->count("levels") && lines->count("base_points"))
      where = "recipe lines " + std::to_string(lines->at("levels")) + " and " +
              std::to_string(lines->at("base_points")) + ": ";
    throw InvalidArgument(where + "levels " + std::to_string(r.levels) + " from base_points " +
                          std::to_string(r.base_points) + " make " + std::to_string(r.top_level_points()) +
                          " points per tile at the top level, more than 2^22 (4,194,304)");
  }
  if (make_keyframe_nominal(r.nominal_counts(), r.keyframes_per_level).size() > kMaxKeyframes)
    throw InvalidArgument(at("keyframes") + "more than " + std::to_string(kMaxKeyframes) +
                          " keyframes in all");
  const std::vector<std::uint32_t> nominal = r.nominal_counts();
  if (patch_widths(r.band, r.erosion, r.edge_gap, nominal).empty()) {
    std::size_t level = 1;  // the first level whose patches are too narrow
    while (!patch_widths(r.band, r.erosion, r.edge_gap, {nominal.begin(), nominal.begin() + level}).empty())
      ++level;
    char text[400];  // every term named, base_points too: a sparse coarsest level is the usual cause
    std::snprintf(text, sizeof text,
                  "recipe: base_points %u with band %g, erosion %g and edge_gap %g leaves level %zu's edge "
                  "patches narrower than half a point spacing (more base_points, a larger band, or a smaller "
                  "erosion or edge_gap, widens them)",
                  unsigned(r.base_points), r.band, r.erosion, r.edge_gap, level - 1);
    throw InvalidArgument(text);
  }
  // Keys that only tune another's pass: alone they would do nothing, silently. Refused when given at all,
  // 0 included, so that a recipe never holds a line that does nothing.
  const auto needs = [&](const char* key, bool parent_on, const char* parent) {
    if (given(key) && !parent_on) throw InvalidArgument(at(key) + key + " needs " + parent);
  };
  needs("separation_push", r.separation > 0, "separation");
  if (r.separation_push > 0 && r.separation_push < r.separation)
    throw InvalidArgument(at("separation_push") + "separation_push " + shortest(r.separation_push) +
                          " must be at least separation " + shortest(r.separation));
  needs("separation_fill", r.separation_push > 0, "separation_push");
  needs("separation_per_level", r.separation_push > 0, "separation_push");
  needs("split_shared", r.separation > 0 || r.glide_separation > 0, "separation or glide_separation");
  const bool track = r.keyframes_per_level > 0;
  if (track && r.levels < 2)  // one level has no density between levels for a point to glide through
    throw InvalidArgument(at("keyframes") +
                          "keyframes need 2 or more levels (a glide track runs between levels)");
  for (const char* key :
       {"glide_sweeps", "glide_separation", "glide_consensus", "glide_corner_consensus", "glide_late"})
    needs(key, track, "a glide track (keyframes)");
  needs("handover_level", r.handover_zone > 0, "handover_zone (a hand-over)");
  needs("handover_slack", r.handover_zone > 0, "handover_zone (a hand-over)");
  if (r.handover_zone) {
    const std::string zone_at = at("handover_zone");
    if (r.levels < 2 || r.levels > 9 || !r.keyframes_per_level)
      throw InvalidArgument(zone_at + "handover_zone needs 2 to 9 levels and a glide track (keyframes)");
    if (r.handover_level + 1 >= r.levels)
      throw InvalidArgument(at("handover_level") + "handover_level " + std::to_string(r.handover_level) +
                            " must be below the top level (" + std::to_string(r.levels - 1) + ")");
    const std::uint32_t m = 1u << (r.levels - 1 - r.handover_level);  // √(N_top / N_j)
    // Subdivision: corner squares and edge bands must not meet (2 · zone + 1 < subtiles per side).
    if (2 * r.handover_zone + 1 >= m) {
      std::uint32_t levels = r.handover_level + 1;
      while ((1u << (levels - 1 - r.handover_level)) <= 2 * r.handover_zone + 1) ++levels;
      throw InvalidArgument(
          zone_at + "handover_zone " + std::to_string(r.handover_zone) + " needs at least " +
          std::to_string(levels) + " levels" +
          (r.handover_level ? " with handover_level " + std::to_string(r.handover_level) : std::string()) +
          ": " + std::to_string(r.levels) + " give " + std::to_string(m) +
          " subtiles per side, and 2 * zone + 1 must be below that (a set without a hand-over has no "
          "handover_zone line)");
    }
    TilesetShape shape;
    const std::vector<std::uint32_t> keyframes = make_keyframe_nominal(nominal, r.keyframes_per_level);
    shape.level_nominal.assign(nominal.begin(), nominal.end());
    shape.keyframe_nominal.assign(keyframes.begin(), keyframes.end());
    shape.handover_level = r.handover_level, shape.handover_slack = r.handover_slack;
    if (shape.handover_keyframe() + 1 < keyframes.size() &&
        keyframes[shape.handover_keyframe()] > Tile::kMaxHandoverRank + 1) {
      throw InvalidArgument(zone_at + "the hand-over keyframe holds " +
                            std::to_string(keyframes[shape.handover_keyframe()]) +
                            " points per subtile, more than a tile set's hand-over addresses (" +
                            std::to_string(Tile::kMaxHandoverRank + 1) +
                            "): fewer base_points, a lower handover_level or less handover_slack");
    }
    if (shape.handover_keyframe() + 1 >= keyframes.size()) {
      // The most slack there is room for: the hand-over keyframe must lie below the top one.
      const auto most = std::int64_t(keyframes.size()) - std::int64_t(shape.handover_keyframe()) +
                        std::int64_t(r.handover_slack) - 2;
      throw InvalidArgument((given("handover_slack") ? at("handover_slack") : zone_at) + "handover_slack " +
                            std::to_string(r.handover_slack) +
                            " puts the hand-over keyframe at or past the top one (" +
                            (most >= 0 ? std::to_string(most) + " at most" : "more keyframes needed") + ")");
    }
  }
}

}  // namespace

bool BakeRecipe::gives_any_key(const std::string& text) {
  for (const std::string& line : text_lines(text))
    if (!words_of(line).empty()) return true;
  return false;
}

bool BakeRecipe::looks_like_recipe(const std::string& text) {
  for (const std::string& line : text_lines(text.substr(0, 4096))) {
    const std::vector<std::string> words = words_of(line);
    if (words.empty()) continue;
    return words.size() == 2 && (words[0] == "seed" || find_rule(words[0]));
  }
  return false;
}

BakeRecipe BakeRecipe::parse(const std::string& text) {
  // Bytes of a baked set where its recipe belongs (arguments swapped, or a .kdmt read as text).
  if (text.rfind("KDMTILES", 0) == 0)
    throw InvalidArgument("recipe: this is a kdm tile-set file (it starts with KDMTILES), not a recipe");
  BakeRecipe r;
  int line_no = 0;
  std::map<std::string, int> seen;  // key -> the line that gave it
  for (std::string line : text_lines(text)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    const std::vector<std::string> words = words_of(line);
    if (words.empty()) continue;
    const std::string where = "recipe line " + std::to_string(line_no) + ": ";
    if (const std::string why = layout_error(line, words); !why.empty()) throw InvalidArgument(where + why);
    const std::string &key = words[0], &value = words[1];
    // A second value would silently win over the first: which one the author meant is not known.
    if (const auto [it, first] = seen.emplace(key, line_no); !first)
      throw InvalidArgument(where + key + " was already given on line " + std::to_string(it->second));
    if (key == "seed") {  // every 64-bit seed, exactly: not through a double
      errno = 0;
      char* end = nullptr;
      r.seed = std::strtoull(value.c_str(), &end, 10);
      if (value.find_first_not_of("0123456789") != std::string::npos || errno == ERANGE)
        throw InvalidArgument(where + "seed must be a whole number in [0, 18446744073709551615], got '" +
                              printable(value) + "'");
      continue;
    }
    const KeyRule* k = find_rule(key);
    if (!k) throw InvalidArgument(where + "unknown key '" + printable(key) + "'");
    // Decimal numbers only: strtod also reads hexadecimal, "inf" and "nan", and stops at a NUL byte.
    if (value.find_first_not_of("0123456789+-.eE") != std::string::npos)
      throw InvalidArgument(where + "'" + printable(value) + "' is not a number");
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(value.c_str(), &end);
    if (end != value.c_str() + value.size())
      throw InvalidArgument(where + "'" + printable(value) + "' is not a number");
    if (errno == ERANGE && std::fabs(v) > 1)
      throw InvalidArgument(where + key + " " + value + " is out of range");
    if (const std::string why = range_error(*k, v, value); !why.empty()) throw InvalidArgument(where + why);
    k->set(r, v);
  }
  check_together(r, &seen);
  return r;
}

void BakeRecipe::validate() const {
  for (const KeyRule& k : kKeyRules)
    if (const std::string why = range_error(k, k.get(*this), shortest(k.get(*this))); !why.empty())
      throw InvalidArgument("recipe: " + why);
  check_together(*this, nullptr);
}

int BakeRecipe::sweeps_for(std::uint64_t level_points) const {
  return static_cast<int>(sweeps *
                          std::clamp(4096.0 / double(std::max<std::uint64_t>(1, level_points)), 1.0, 64.0));
}

std::string BakeRecipe::to_text() const {
  std::ostringstream s;
  s << "seed " << seed << "\ncolours " << colours << "\nlevels " << levels << "\nbase_points " << base_points
    << "\ntemperature " << shortest(temperature) << "\nsweeps " << sweeps << "\nband " << shortest(band)
    << "\nerosion " << shortest(erosion) << "\n";
  // Written only when set, so recipes from before the key keep their text (and their bytes).
  if (edge_gap != kFirstEdgeGap) s << "edge_gap " << shortest(edge_gap) << "\n";
  if (min_distance > 0) s << "min_distance " << shortest(min_distance) << "\n";
  if (rank_context) s << "rank_context " << rank_context << "\n";
  if (separation > 0) s << "separation " << shortest(separation) << "\n";
  if (separation_push > 0) s << "separation_push " << shortest(separation_push) << "\n";
  if (split_shared) s << "split_shared 1\n";
  if (separation_fill) s << "separation_fill 1\n";
  if (separation_per_level) s << "separation_per_level 1\n";
  if (fill_holes > 0) s << "fill_holes " << shortest(fill_holes) << "\n";
  if (keyframes_per_level)
    s << "keyframes " << keyframes_per_level << "\nglide_sweeps " << glide_sweeps << "\n";
  if (glide_separation > 0) s << "glide_separation " << shortest(glide_separation) << "\n";
  if (glide_consensus) s << "glide_consensus " << glide_consensus << "\n";
  if (glide_corner_consensus) s << "glide_corner_consensus " << glide_corner_consensus << "\n";
  if (glide_late > 0) s << "glide_late " << shortest(glide_late) << "\n";
  if (handover_zone) s << "handover_zone " << handover_zone << "\n";
  if (handover_level) s << "handover_level " << handover_level << "\n";
  if (handover_slack) s << "handover_slack " << handover_slack << "\n";
  return s.str();
}

std::vector<std::uint32_t> BakeRecipe::nominal_counts() const {
  std::vector<std::uint32_t> n;
  for (std::uint32_t k = 0; k < levels; ++k) n.push_back(base_points << (2 * k));
  return n;
}

namespace {

class Baker {
 public:
  BakeReport report;  ///< what the separation passes did
  Baker(const BakeRecipe& recipe, int threads, const std::function<void(double)>& progress)
      : recipe_(recipe),
        threads_(threads),
        progress_(progress),
        nominal_(recipe.nominal_counts()),
        widths_(patch_widths(recipe.band, recipe.erosion, recipe.edge_gap, nominal_)),
        runs_(plan_runs(recipe.colours)) {
    if (widths_.empty()) throw InvalidArgument("recipe: the patches of some level are too narrow");
    for (std::uint32_t k = 0; k < recipe.levels; ++k)
      for (const BakeRun& run : runs_) total_work_ += work(k, run);
    for (std::uint32_t count : make_keyframe_nominal(nominal_, recipe_.keyframes_per_level))
      total_work_ += glide_work(count);
  }

  TilesetData bake() {
    shape_.colours = recipe_.colours;
    shape_.levels = recipe_.levels;
    shape_.level_nominal.assign(nominal_.begin(), nominal_.end());
    const bool push = recipe_.separation_push > 0, per_level = push && recipe_.separation_per_level;
    for (std::uint32_t k = 0; k < recipe_.levels; ++k) {
      levels_.emplace_back(recipe_.colours);
      for_each_run(
          runs_, threads_, [&](std::size_t r, int threads) { return sample_run(k, r, threads); },
          [&](std::size_t r, Sampled& sampled) {
            keep_patches(k, r, sampled);
            done_work_ += work(k, runs_[r]);
            if (progress_) progress_(done_work_ / total_work_);
          });
      if (per_level) separate();  // the levels below were parted already: only level k's points move
    }
    if (push && !per_level)
      separate();
    else if (!push)
      report.removed = drop_close_pairs(levels_, recipe_.colours, shape_, recipe_.separation);
    const std::vector<std::uint32_t> keyframes = make_keyframe_nominal(nominal_, recipe_.keyframes_per_level);
    shape_.keyframe_nominal.assign(keyframes.begin(), keyframes.end());
    for (std::size_t g = 0; g < keyframes.size(); ++g) {
      relax_keyframe(levels_, runs_, widths_, shape_, g, recipe_.glide_sweeps, recipe_.seed, threads_,
                     Consensus{recipe_.glide_consensus, recipe_.glide_corner_consensus}, recipe_.glide_late);
      done_work_ += glide_work(keyframes[g]);
      if (progress_) progress_(done_work_ / total_work_);
    }
    const SeparationResult glides =
        drop_close_glides(levels_, recipe_.colours, shape_, recipe_.glide_separation, recipe_.split_shared);
    report.glide_removed = glides.removed, report.glide_split = glides.split;
    shape_.handover_zone = recipe_.handover_zone, shape_.handover_level = recipe_.handover_level;
    shape_.handover_slack = recipe_.handover_slack;
    TilesetData set = assemble();
    if (set.handover_zone) add_handover(set);
    return set;
  }

  /// Parts the close pairs of the levels sampled so far (push_close_pairs_apart), adding to the report.
  void separate() {
    const SeparationResult r =
        push_close_pairs_apart(levels_, recipe_.colours, shape_, recipe_.separation, recipe_.separation_push,
                               recipe_.split_shared, recipe_.separation_fill);
    report.removed += r.removed, report.moved += r.moved, report.split += r.split;
  }

  /// The hand-over tables (docs/design.md §3, "Unbounded zoom"), in the file's encoding.
  void add_handover(TilesetData& set) const {
    const Subdivision sub = set.subdivision();
    const std::vector<TileHandover> plan = plan_handover(set);
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      Tile& tile = set.tiles[t];
      for (std::size_t r = 0; r < tile.points.size(); ++r) {
        const std::uint32_t j = plan[t].target[r] >> 16, q = plan[t].target[r] & 0xFFFF;
        const std::int64_t dx = std::int64_t(j % sub.m) - TilesetShape::subtile_of(tile.points[r].x, sub.m);
        const std::int64_t dy = std::int64_t(j / sub.m) - TilesetShape::subtile_of(tile.points[r].y, sub.m);
        if (q > Tile::kMaxHandoverRank)  // parse refuses recipes whose hand-over keyframe holds more
          throw InvalidArgument("hand-over: a subtile hands over more than " +
                                std::to_string(Tile::kMaxHandoverRank + 1) +
                                " points (fewer base_points, a lower handover_level or less handover_slack)");
        if (std::abs(dx) > 2 || std::abs(dy) > 2)
          throw InvalidArgument("hand-over: a point's sub-point lies more than two subtiles away");
        tile.handover.push_back(static_cast<std::uint16_t>(q * 25 + (dy + 2) * 5 + (dx + 2)));
      }
      tile.appearing.assign(plan[t].appearing.begin(), plan[t].appearing.end());
    }
  }

 private:
  double work(std::uint32_t level, const BakeRun& run) const {
    return double(run.w * run.h) * nominal_[level] * recipe_.sweeps_for(nominal_[level]);
  }

  /// A keyframe's relaxation: each stage's own tori, and with consensus the later stages' too.
  double glide_work(std::uint32_t count) const {
    const Consensus consensus{recipe_.glide_consensus, recipe_.glide_corner_consensus};
    double area = 0;
    for (const BakeRun& run : runs_)
      for (int stage = 0; stage <= run.stage; ++stage)
        if (stage == run.stage || consensus.covers(count, stage)) area += run.w * run.h;
    return area * count * recipe_.glide_sweeps;
  }

  /// A sampled run: its torus, the points it conditioned on and what it drew.
  struct Sampled {
    Colouring col;
    RankingInput rank;
    SampleResult result;
  };

  /// Samples run `r` of level k (reads earlier levels and stages only; safe to call concurrently).
  Sampled sample_run(std::uint32_t k, std::size_t r, int threads) const {
    const BakeRun& run = runs_[r];
    Colouring col = Colouring::torus(recipe_.colours, run.w, run.h, run.grid);
    // Context: every earlier level, and this level's patches of earlier stages (with their keys).
    RankingInput rank;
    rank.width = run.w, rank.height = run.h;
    for (std::uint32_t j = 0; j < k; ++j)
      gather(levels_[j], col, {true, true, true, true}, 0, 0, run.w, run.h, rank.fixed, nullptr);
    std::array<bool, 4> earlier{};
    for (int kind = 0; kind < run.stage; ++kind) earlier[kind] = true;
    gather(levels_[k], col, earlier, 0, 0, run.w, run.h, rank.timed, &rank.timed_keys);

    SamplerOptions o;
    o.extent[0] = run.w, o.extent[1] = run.h;
    const std::int64_t present = static_cast<std::int64_t>((rank.fixed.size() + rank.timed.size()) / 2);
    o.n = std::int64_t(run.w * run.h) * nominal_[k] - present;
    if (o.n <= 0) {
      // fill_holes near its lower limit also fills a blue-noise set's ordinary gaps (up to 0.85 d_hex).
      const std::string fill = recipe_.fill_holes > 0
                                   ? " (fill_holes " + shortest(recipe_.fill_holes) +
                                         " added points in ordinary gaps: try 0.8 or more, or leave it out)"
                                   : "";
      throw InvalidArgument("recipe: a patch's context already holds all of its level's points" + fill);
    }
    o.temperature = recipe_.temperature;
    o.sweeps = recipe_.sweeps_for(nominal_[k]);
    o.coarse_sweeps = o.sweeps;
    // The arithmetic of the first bakes: a recipe must give the same tiles in every kdm version.
    o.numerics = Numerics::kOriginal;
    o.count_balance = false;  // a run with nothing fixed yet keeps the first bakes' schedule too
    o.coarsest_sweeps = std::max(kFirstCoarsestSweeps, o.sweeps);
    // Start two grid levels below the finest, not at 32 nodes: the coarse levels' heavy kernels cannot
    // resolve a residual density confined to patches between fixed bands, and spread the new points
    // unevenly between patches (docs/design.md §3).
    const double nodes_per_tile = std::sqrt(nominal_[k] * 7.07 / o.peak_density);  // sampler.h, `resolution`
    o.coarsest_grid =
        std::max(o.coarsest_grid, static_cast<int>(nodes_per_tile * std::min(run.w, run.h) / 4));
    o.threads = threads;
    o.seed = mix64(recipe_.seed ^ mix64(0x42414b45ull + 4096ull * k + r));  // "BAKE"
    for (std::size_t i = 0; i < rank.fixed.size(); i += 2)
      o.fixed_points.insert(o.fixed_points.end(), {rank.fixed[i] / run.w, rank.fixed[i + 1] / run.h});
    for (std::size_t i = 0; i < rank.timed.size(); i += 2)
      o.fixed_points.insert(o.fixed_points.end(), {rank.timed[i] / run.w, rank.timed[i + 1] / run.h});
    return {col, std::move(rank), sample(o)};
  }

  /// Keeps (and ranks) the patches of run `r`'s stage that no earlier run made.
  void keep_patches(std::uint32_t k, std::size_t r, Sampled& sampled) {
    const BakeRun& run = runs_[r];
    const Colouring& col = sampled.col;
    RankingInput& rank = sampled.rank;
    const SampleResult& result = sampled.result;
    // The new points by the patch they fall in; only patches of this run's stage not made before.
    LevelPatches& level = levels_[k];
    std::map<std::pair<int, std::size_t>, std::vector<std::pair<double, double>>> found;  // -> torus xy
    std::map<std::pair<int, std::size_t>, std::vector<std::pair<double, double>>> relative;
    std::map<std::pair<int, std::size_t>, std::pair<std::int64_t, std::int64_t>> anchors;
    // Every point the run held fixed, then each new point kept: a new point too close to any is dropped.
    const double hex_spacing = std::sqrt(2.0 / (std::sqrt(3.0) * nominal_[k]));
    SpacingGuard guard(run.w, run.h, recipe_.min_distance * hex_spacing,
                       std::size_t(run.w * run.h) * nominal_[k]);
    for (const std::vector<double>* fixed : {&rank.fixed, &rank.timed})
      for (std::size_t i = 0; i < fixed->size(); i += 2) guard.add((*fixed)[i], (*fixed)[i + 1]);
    // With rank_context, the run's other new points (regions of later stages, patches made by other runs)
    // are ranked too, as stand-ins for the points those regions will get: ranked alone, a patch's points
    // next to such a region face a void there and come first, and the patch's middle (a tile edge, for an
    // edge patch) fills last.
    std::vector<double> context;
    for (std::size_t i = 0; i < result.size(); ++i) {
      const double x = result.points[2 * i] * run.w, y = result.points[2 * i + 1] * run.h;
      Placement p;
      const auto stage_kind = static_cast<PatchKind>(run.stage);
      const bool placed = place_new_point(x, y, stage_kind, widths_[k], col, p);
      if (!placed || level.of(p.kind)[p.patch].done) {
        if (recipe_.rank_context && (placed || p.kind > stage_kind)) context.insert(context.end(), {x, y});
        continue;
      }
      const int kind = static_cast<int>(p.kind);
      // A patch can appear at two anchors of a small torus (e.g. both interiors of one tile type): keep
      // the first anchor's copy only.
      const std::pair<std::int64_t, std::int64_t> at{(p.anchor_x % run.w + run.w) % run.w,
                                                     (p.anchor_y % run.h + run.h) % run.h};
      if (anchors.try_emplace({kind, p.patch}, at).first->second != at) {
        if (recipe_.rank_context) context.insert(context.end(), {x, y});
        continue;
      }
      // A point deep inside an earlier kind's region sits where another tile has other points near it
      // (its patch was sampled with this tile's context only): finer levels could not see it.
      if (recipe_.min_distance > 0 && p.slip > kMaxSlip / std::sqrt(double(nominal_[k]))) continue;
      if (!guard.clear(x, y)) continue;
      guard.add(x, y);
      found[{kind, p.patch}].push_back({x, y});
      relative[{kind, p.patch}].push_back({p.rx, p.ry});
    }
    if (recipe_.fill_holes > 0) {
      // A hole the run froze in a patch it keeps gets a point, deepest first; each changes the holes
      // around it, so they are found again after each.
      std::vector<double> all = rank.fixed;
      all.insert(all.end(), rank.timed.begin(), rank.timed.end());
      for (std::size_t i = 0; i < result.size(); ++i)
        all.insert(all.end(), {result.points[2 * i] * run.w, result.points[2 * i + 1] * run.h});
      HoleFinder holes(run.w, run.h, 0.25 * hex_spacing, 2 * hex_spacing, all);
      const auto stage_kind = static_cast<PatchKind>(run.stage);
      for (bool added = true; added;) {
        added = false;
        const std::vector<double> centres = holes.centres_beyond(recipe_.fill_holes * hex_spacing);
        for (std::size_t c = 0; c < centres.size() && !added; c += 2) {
          Placement p;
          if (!place_new_point(centres[c], centres[c + 1], stage_kind, widths_[k], col, p) ||
              level.of(p.kind)[p.patch].done)
            continue;
          const std::pair<std::int64_t, std::int64_t> at{(p.anchor_x % run.w + run.w) % run.w,
                                                         (p.anchor_y % run.h + run.h) % run.h};
          if (anchors.try_emplace({static_cast<int>(p.kind), p.patch}, at).first->second != at) continue;
          found[{static_cast<int>(p.kind), p.patch}].push_back({centres[c], centres[c + 1]});
          relative[{static_cast<int>(p.kind), p.patch}].push_back({p.rx, p.ry});
          holes.add(centres[c], centres[c + 1]);
          added = true;
        }
      }
    }
    rank.filter_width = kFilterWidth / std::sqrt(k ? nominal_[k - 1] : nominal_[0] / 4.0);
    rank.filter_width_end = kFilterWidth / std::sqrt(double(nominal_[k]));
    if (recipe_.rank_context == 1) {
      // One ranking of every new point; each patch keeps its own points' order, keyed within the patch.
      rank.candidates = context;
      std::vector<std::pair<const std::pair<int, std::size_t>*, std::size_t>> owner(context.size() / 2);
      for (const auto& [id, points] : found)
        for (std::size_t i = 0; i < points.size(); ++i) {
          rank.candidates.insert(rank.candidates.end(), {points[i].first, points[i].second});
          owner.push_back({&id, i});
        }
      std::map<std::pair<int, std::size_t>, std::vector<std::size_t>> order_in_patch;
      for (std::uint32_t c : progressive_order(rank))
        if (owner[c].first) order_in_patch[*owner[c].first].push_back(owner[c].second);
      for (const auto& [id, order] : order_in_patch) {
        Patch& patch = level.of(static_cast<PatchKind>(id.first))[id.second];
        const auto& rel = relative[id];
        for (std::size_t s = 0; s < order.size(); ++s)
          patch.add(rel[order[s]].first, rel[order[s]].second, rank_key(s, order.size()));
      }
    } else {
      for (const auto& [id, points] : found) {
        if (recipe_.rank_context == 2) {  // the run's other new points, present in proportion
          rank.pending = context;
          for (const auto& [other, other_points] : found)
            if (other != id)
              for (const auto& [x, y] : other_points) rank.pending.insert(rank.pending.end(), {x, y});
        }
        rank.candidates.clear();
        for (const auto& [x, y] : points) rank.candidates.insert(rank.candidates.end(), {x, y});
        const std::vector<std::uint32_t> order = progressive_order(rank);
        Patch& patch = level.of(static_cast<PatchKind>(id.first))[id.second];
        const auto& rel = relative[id];
        for (std::size_t s = 0; s < order.size(); ++s)
          patch.add(rel[order[s]].first, rel[order[s]].second, rank_key(s, order.size()));
      }
    }
    for (const auto& [id, points] : found) level.of(static_cast<PatchKind>(id.first))[id.second].done = true;
  }

  /// Every tile (sw, se, ne, nw): its share of the patches around it, level by level, sorted by key.
  TilesetData assemble() {
    TilesetData set;
    static_cast<TilesetShape&>(set) = shape_;
    set.recipe = recipe_.to_text();
    set.generator_version = version_string();
    const std::size_t count = std::size_t(set.colours) * set.colours * set.colours * set.colours;
    for (std::size_t t = 0; t < count; ++t) {
      const Colouring col = Colouring::around_tile(set.colours, t);
      Tile tile;
      std::vector<PatchPointRef> ranked;  // where each point of the tile comes from, by rank
      for (const LevelPatches& level : levels_) {
        std::vector<double> xy;
        std::vector<std::uint16_t> keys;
        std::vector<PatchPointRef> refs;
        gather(level, col, {true, true, true, true}, 0, 0, 1, 1, xy, &keys, &refs);
        std::vector<std::size_t> order(keys.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        const auto point = [&](std::size_t i) { return TilePoint::from_unit(xy[2 * i], xy[2 * i + 1]); };
        std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
          const TilePoint pa = point(a), pb = point(b);
          return std::tie(keys[a], pa.y, pa.x) < std::tie(keys[b], pb.y, pb.x);
        });
        for (std::size_t i : order) {
          tile.points.push_back(point(i));
          tile.keys.push_back(keys[i]);
          ranked.push_back(refs[i]);
        }
        tile.level_end.push_back(static_cast<std::uint32_t>(tile.points.size()));
      }
      for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g)
        for (std::uint32_t c = 0, n = set.offsets_at_keyframe(tile, g); c < n; ++c)
          for (int axis = 0; axis < 2; ++axis) {
            const PatchPointRef& ref = ranked[c];
            KDM_CHECK(ref.patch->frames.size() > g && !ref.patch->frames[g].empty());
            const double u =
                (axis ? ref.anchor_y : ref.anchor_x) + ref.patch->frames[g][2 * ref.index + axis];
            const double stable = axis ? tile.points[c].unit_y() : tile.points[c].unit_x();
            const std::int64_t offset = std::llround((u - stable) / set.glide_unit(g));
            KDM_CHECK(offset >= -127 && offset <= 127);  // keyframes.cpp keeps offsets within kMaxOffset
            tile.glide.push_back(static_cast<std::int8_t>(offset));
          }
      set.tiles.push_back(std::move(tile));
    }
    return set;
  }

  const BakeRecipe& recipe_;
  int threads_;
  const std::function<void(double)>& progress_;
  std::vector<std::uint32_t> nominal_;
  std::vector<PatchWidths> widths_;
  std::vector<BakeRun> runs_;
  std::vector<LevelPatches> levels_;
  TilesetShape shape_;  ///< colours, level and keyframe counts: what the tiles fit into
  double total_work_ = 0, done_work_ = 0;
};

}  // namespace

TilesetData bake_tileset(const BakeRecipe& recipe, int threads, const std::function<void(double)>& progress,
                         BakeReport* report) {
  recipe.validate();  // a recipe made in code is held to parse's rules
  check_thread_count(threads);
  Baker baker(recipe, threads, progress);
  TilesetData set = baker.bake();
  if (report) *report = baker.report;
  return set;
}

}  // namespace kdm::gen
