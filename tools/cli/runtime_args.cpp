#include "runtime_args.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "commands.h"

namespace kdm::cli {

std::unique_ptr<RuntimeDensity> make_runtime_density(const tools::DensitySpec& spec, double x0, double y0,
                                                     double x1, double y1) {
  auto d = std::make_unique<RuntimeDensity>();
  d->spec = &spec;
  d->x0 = x0, d->y0 = y0, d->x1 = x1, d->y1 = y1;
  d->max_value = spec.max_value(), d->mean_value = spec.mean_value();
  using Kind = tools::DensitySpec::Kind;
  switch (spec.kind) {
    case Kind::kConstant:
      d->density.kind = QueryDensity::Kind::kConstant;
      d->density.constant = spec.constant;
      return d;
    case Kind::kRamp:
    case Kind::kRadial:
      d->density.kind = QueryDensity::Kind::kCallback;
      d->density.callback = [](void* user, double x, double y) {
        const RuntimeDensity& r = *static_cast<const RuntimeDensity*>(user);
        const double u = std::clamp((x - r.x0) / (r.x1 - r.x0), 0.0, 1.0);
        const double v = std::clamp((y - r.y0) / (r.y1 - r.y0), 0.0, 1.0);
        return r.spec->map_at(u, v);
      };
      d->density.user = d.get();
      d->density.callback_max = 1;
      return d;
    case Kind::kImage:
      break;
  }
  d->image.width = spec.width, d->image.height = spec.height;
  d->image.x0 = x0, d->image.y0 = y0, d->image.x1 = x1, d->image.y1 = y1;
  d->image.values = spec.values.data();  // row 0 at y0, as DensityImageView has it
  if (make_density_max_mip(d->image, d->mip) != Status::kOk) throw CommandError("density image is invalid");
  d->density.kind = QueryDensity::Kind::kImage;
  d->density.image = &d->image;
  return d;
}

void parse_rect(const std::string& text, const char* option, double r[4]) {
  std::istringstream in(text);
  char c[3] = {0, 0, 0};
  const bool parsed = static_cast<bool>(in >> r[0] >> c[0] >> r[1] >> c[1] >> r[2] >> c[2] >> r[3]) &&
                      c[0] == ',' && c[1] == ',' && c[2] == ',' && (in >> std::ws).eof();
  if (!parsed || !(std::isfinite(r[0]) && std::isfinite(r[1]) && std::isfinite(r[2]) && std::isfinite(r[3])))
    throw CommandError(std::string(option) + " must be x0,y0,x1,y1 (four finite numbers), got '" + text +
                       "'");
  if (!(r[2] > r[0] && r[3] > r[1]))
    throw CommandError(std::string(option) + " is empty or inverted (needs x0 < x1 and y0 < y1): '" + text +
                       "'");
}

const Tileset& tileset_for(const std::string& path, Tileset& storage) {
  if (path.empty()) return Tileset::builtin();
  std::string detail;
  const Status s = Tileset::load_file(path, storage, &detail);
  if (s != Status::kOk) throw CommandError("'" + path + "': " + status_message(s) + " (" + detail + ")");
  return storage;
}

}  // namespace kdm::cli
