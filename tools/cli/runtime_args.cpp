#include "runtime_args.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "commands.h"

namespace kdm::cli {

void parse_rect(const std::string& text, const char* option, double r[4]) {
  std::istringstream in(text);
  char c[3] = {0, 0, 0};
  const bool parsed = static_cast<bool>(in >> r[0] >> c[0] >> r[1] >> c[1] >> r[2] >> c[2] >> r[3]) &&
                      c[0] == ',' && c[1] == ',' && c[2] == ',' && (in >> std::ws).eof();
  if (!parsed || !(std::isfinite(r[0]) && std::isfinite(r[1]) && std::isfinite(r[2]) && std::isfinite(r[3])))
    throw CommandError(std::string(option) + " must be x0,y0,x1,y1 (four finite numbers), got '" + text +
                       "'");
  if (!(r[2] > r[0] && r[3] > r[1])) {
    // Far from 0, two numbers that differ as typed can be one double: say so rather than "inverted".
    long double typed[4];
    std::istringstream again(text);
    for (long double& v : typed) again >> v >> c[0];
    const bool rounded = (r[2] == r[0] && typed[2] > typed[0]) || (r[3] == r[1] && typed[3] > typed[1]);
    throw CommandError(std::string(option) + " is empty or inverted (needs x0 < x1 and y0 < y1" +
                       (rounded ? "; numbers this far from 0 that differ by less than a double resolves are "
                                  "equal"
                                : "") +
                       "): '" + text + "'");
  }
}

const Tileset& tileset_for(const std::string& path, Tileset& storage) {
  if (path.empty()) {
    const Tileset& builtin = Tileset::builtin();
    if (builtin.empty()) throw CommandError("not enough memory to decode the built-in tile set");
    return builtin;
  }
  std::string detail;
  const Status s = Tileset::load_file(path == "-" ? "/dev/stdin" : path, storage, &detail);
  if (s != Status::kOk) throw tileset_error(path, s, detail, {});
  return storage;
}

void warn_without_glide_track(const char* command, const Tileset& tiles, QueryMode mode) {
  if (mode == QueryMode::kSmooth && !tiles.has_glide_track())
    std::fprintf(stderr,
                 "%s: warning: the tile set has no glide track: smooth mode gives stable positions (bake it "
                 "with keyframes)\n",
                 command);
}

}  // namespace kdm::cli
