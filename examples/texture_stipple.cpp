// Stippling a textured, lit sphere in its texture space while the camera flies in 100×.
//
// Each dot is a kdm point of the sphere's (u, v) texture space, so it stays on its spot of the surface. Its
// density there is chosen per frame so that on screen the dots keep one size and spacing: (dots per unit
// screen area) × (screen area per unit texture area, from the projection) × darkness. As the camera nears
// the surface that density grows 10,000-fold; smooth mode glides the points continuously with it and,
// past the tile set's top level, hands them over to subtiles, so each frame moves each dot a little. A dot
// that appears grows in (its area from 0 to full as its density rises 20% past its emission threshold)
// instead of popping up.
//
// Per frame it prints the query's point count, the deepest subtile depth, the dot density on screen where
// the tone is fixed (also relative to its target D × darkness), and the largest motion of a dot over the
// surface since the previous frame, in its spacing along the way it moved (near the silhouette apart). With
// --check it exits non-zero if the relative density of the last frame differs from the first's by more than
// 10% or a dot away from the silhouette moves half a spacing or more in one frame (a motion that needs some
// 300 frames for the 100× zoom: at 24, dots move 1.7-2.9 spacings a frame), or, with --colours, an
// ink's dots on screen are more than 10% off D × its cover in a frame where it expects 100 or more.
//
// With --colours the checker is orange and blue, and the dots are cyan, magenta, yellow and black: four
// classes of one query (kdm::query_classes), whose densities one joint callback gives from the shaded
// colour (CMYK with full under-colour removal), so the inks together are one blue-noise set and each
// follows its share of the colour.
//
//   texture_stipple [--tileset FILE] [--frames K] [--size PIXELS] [--dots-per-pixel-area D] [--colours]
//                   [--check] -o DIR
#include <kdm/runtime/class_query.h>
#include <kdm/runtime/query.h>
#include <kdm/runtime/tileset.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

namespace {

struct Vec {
  double x, y, z;
  friend Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
  friend double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  friend Vec cross(Vec a, Vec b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  friend Vec normalized(Vec a) { return (1 / std::sqrt(dot(a, a))) * a; }
};

// Texture space is Mercator's (u = longitude, v = atanh(sin latitude)): conformal, so texture-space blue
// noise stays round on the sphere, and not stretched at all on the equator, where the camera looks.
constexpr double kPi = 3.14159265358979323846;
constexpr double kChecker = kPi / 6;  // the checker's square side, texture units
constexpr double kMaxV = 3.5;         // latitude ±86.5°: the caps beyond never face this camera path
const Vec kLight = normalized(Vec{0.6, -0.6, 0.55});  // from the upper left, seen from the camera
constexpr double kRim = 0.25;  // the silhouette's band: surface turned more than 75.5° from the eye

Vec surface(double u, double v) {  // the point of the unit sphere at (u, v), also its normal
  const double c = 1 / std::cosh(v);
  return {c * std::cos(u), c * std::sin(u), std::tanh(v)};
}
bool light_square(double u, double v) {
  return ((static_cast<long>(std::floor(u / kChecker)) + static_cast<long>(std::floor(v / kChecker))) & 1) ==
         0;
}
double shading(Vec normal) {  // Lambert's, and some ambient light
  return 0.1 + 0.9 * std::max(0.0, dot(normal, kLight));
}
double tone(double u, double v, Vec normal) {  // texture × shading, 0 black … 1 white
  return (light_square(u, v) ? 0.8 : 0.4) * shading(normal);
}

// --colours: the checker's colours, shaded, as the cover of each ink (0 … 1) in class order. Full
// under-colour removal: black takes the grey all three channels share, and at most two of cyan, magenta
// and yellow remain. The order is the classes' (class 0 first): the inks by their share of the dots,
// least first (magenta .20, yellow .24, cyan .24, black .33, averaged over the frames), as `kdm stipple
// --colours` orders them, so that a small share is not left the count errors of the sums before it.
constexpr int kInks = 4;
constexpr const char* kInkNames[kInks] = {"magenta", "yellow", "cyan", "black"};
constexpr unsigned char kInkRgb[kInks][3] = {{255, 0, 255}, {255, 255, 0}, {0, 255, 255}, {0, 0, 0}};
void ink_cover(double u, double v, Vec normal, double cover[kInks]) {
  const double light = shading(normal);
  const double r = (light_square(u, v) ? 0.95 : 0.20) * light, g = (light_square(u, v) ? 0.75 : 0.45) * light,
               b = (light_square(u, v) ? 0.35 : 0.70) * light;
  const double k = 1 - std::max({r, g, b}), rest = 1 - k;  // rest > 0: the shading is at least 0.1
  cover[0] = (1 - g - k) / rest, cover[1] = (1 - b - k) / rest, cover[2] = (1 - r - k) / rest, cover[3] = k;
}
// The dot density's share at (u, v): darkness, or with colours every ink's cover together.
double darkness(double u, double v, Vec normal, bool colours) {
  if (!colours) return 1 - tone(u, v, normal);
  double cover[kInks];
  ink_cover(u, v, normal, cover);
  return cover[0] + cover[1] + cover[2] + cover[3];
}

// A pinhole camera at distance `r` from the sphere's centre along `dir`, looking at the centre.
struct Camera {
  Vec eye, forward, right, up;
  double focal = 1, half = 1;  // pixels per unit of tan(angle off axis); half the image side
  Camera(Vec dir, double r, double size) : focal(size), half(size / 2) {  // 53° field of view
    eye = r * dir, forward = -1 * dir, right = normalized(cross(forward, Vec{0, 0, 1})),
    up = cross(right, forward);
  }
  void project(Vec p, double& sx, double& sy) const {  // every point of the sphere is in front of the eye
    const Vec d = p - eye;
    const double z = dot(d, forward);
    sx = half + focal * dot(d, right) / z, sy = half - focal * dot(d, up) / z;
  }
  bool cast(double sx, double sy, Vec& hit) const {  // the sphere's point seen at pixel (sx, sy)
    const Vec d = normalized(forward + ((sx - half) / focal) * right + ((half - sy) / focal) * up);
    const double b = dot(eye, d), disc = b * b - (dot(eye, eye) - 1);
    if (disc < 0) return false;
    hit = eye + (-b - std::sqrt(disc)) * d;
    return true;
  }
  bool on_screen(double sx, double sy) const { return sx >= 0 && sy >= 0 && sx < 2 * half && sy < 2 * half; }
};
void texture_coords(Vec p, double& u, double& v) {
  u = std::atan2(p.y, p.x), v = std::atanh(std::clamp(p.z, -0.9999, 0.9999));
}

struct Frame {
  Camera camera;
  double dots = 0;  // D, dots per pixel area at full darkness (with colours: per ink, at full cover)
  bool colours = false;
};

// Dots per unit texture area at (u, v) and full darkness: D × (screen area per unit texture area). A
// surface element dA at p, facing the eye by (eye − p)·n and at depth z, covers f² (eye − p)·n / z³ · dA
// pixels; Mercator's dA is h² du dv, h = 1 / cosh v.
double full_density(const Frame& f, double v, Vec p) {
  const double facing = dot(f.camera.eye - p, p);
  if (facing <= 0) return 0;  // the far side: no dots
  const double z = dot(p - f.camera.eye, f.camera.forward), h = 1 / std::cosh(v);
  return f.dots * f.camera.focal * f.camera.focal * facing / (z * z * z) * h * h;
}
// The dots' density: full_density × darkness (with colours, of all inks together).
double texture_density(void* user, double u, double v) {
  const Frame& f = *static_cast<const Frame*>(user);
  const Vec p = surface(u, v);
  return full_density(f, v, p) * darkness(u, v, p, f.colours);
}
// With colours, each ink's: full_density × its cover (a joint density: one call for the four classes).
void ink_densities(void* user, double u, double v, double* values) {
  const Frame& f = *static_cast<const Frame*>(user);
  const Vec p = surface(u, v);
  const double full = full_density(f, v, p);
  ink_cover(u, v, p, values);
  for (int k = 0; k < kInks; ++k) values[k] *= full;
}
// The bounds: with the eye at distance r, facing = eye·p − 1 ≤ r − 1 and z = r − p·dir ≥ r − 1 and h ≤ 1,
// so full_density ≤ D f² / (r − 1)², reached facing the eye on the equator. An ink's cover is at most 1,
// the darkness too, and the inks' sum at most 3 (black and two of the others).
double full_density_bound(const Frame& f) {
  const double h = std::sqrt(dot(f.camera.eye, f.camera.eye)) - 1;
  return f.dots * f.camera.focal * f.camera.focal / (h * h);
}
double texture_density_bound(const Frame& f) {
  return full_density_bound(f) * (f.colours ? 3 : 1);
}

// The texture rectangle holding every visible point: its outline is where the screen's border meets the
// sphere and where the silhouette lies inside the screen, so it is the bounding box of those (sampled,
// then widened by 2% against the gaps between samples). Longitude stays within (−π, π): the seam and the
// poles never face the camera on this path.
void visible_region(const Camera& c, kdm::QueryParams& q) {
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  auto add = [&](Vec p) {
    double u, v;
    texture_coords(p, u, v);
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  };
  const int n = 256;
  const double side = 2 * c.half;
  for (int i = 0; i <= n; ++i) {
    const double t = side * i / n;
    const double border[4][2] = {{t, 0}, {t, side}, {0, t}, {side, t}};
    Vec p;
    for (const auto& b : border)
      if (c.cast(b[0], b[1], p)) add(p);
  }
  const double r = std::sqrt(dot(c.eye, c.eye)), rim = std::sqrt(1 - 1 / (r * r));
  for (int i = 0; i < 4 * n; ++i) {  // the silhouette: the circle of points whose tangent plane holds the eye
    const double a = 2 * kPi * i / (4 * n);
    const Vec p = (1 / (r * r)) * c.eye + rim * std::cos(a) * c.right + rim * std::sin(a) * c.up;
    double sx, sy;
    c.project(p, sx, sy);
    if (c.on_screen(sx, sy)) add(p);
  }
  const double mu = 0.02 * (u1 - u0), mv = 0.02 * (v1 - v0);
  q.x0 = std::max(u0 - mu, -kPi), q.x1 = std::min(u1 + mu, kPi);
  q.y0 = std::max(v0 - mv, -kMaxV), q.y1 = std::min(v1 + mv, kMaxV);
}

struct Dot {  // a point of one frame, kept to follow it into the next
  kdm::PointId id;
  double u, v;
  bool shown;
};
bool id_less(const Dot& a, const Dot& b) {
  return std::tie(a.id.depth, a.id.tile_x, a.id.tile_y, a.id.rank) <
         std::tie(b.id.depth, b.id.tile_x, b.id.tile_y, b.id.rank);
}

// A dot of ink `rgb` (one channel: black) on the picture, as inks print: each channel times the ink's.
void draw_disc(std::vector<unsigned char>& image, int size, int channels, double cx, double cy, double radius,
               const unsigned char* rgb) {
  const int x0 = std::max(0, int(cx - radius - 1)), x1 = std::min(size - 1, int(cx + radius + 1));
  const int y0 = std::max(0, int(cy - radius - 1)), y1 = std::min(size - 1, int(cy + radius + 1));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {  // coverage from the distance to the edge: antialiased over a pixel
      const double cover = std::clamp(radius + 0.5 - std::hypot(x + 0.5 - cx, y + 0.5 - cy), 0.0, 1.0);
      for (int c = 0; c < channels; ++c) {
        unsigned char& px = image[(std::size_t(y) * size + x) * channels + c];
        px = static_cast<unsigned char>(std::lround(px * (1 - cover * (1 - rgb[c] / 255.0))));
      }
    }
}

bool parse_number(const char* text, double lo, double hi, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0' && out >= lo && out <= hi;
}

/// The usage line, after `problem` on stderr (exit status 2), or alone on stdout for --help (0).
int usage(const char* problem) {
  std::FILE* to = problem ? stderr : stdout;
  if (problem) std::fprintf(to, "texture_stipple: %s\n", problem);
  std::fprintf(to,
               "usage: texture_stipple [--tileset FILE] [--frames K (2-100000, default 24)] "
               "[--size PIXELS (32-4096, default 512)] [--dots-per-pixel-area D (0.001-1, default 0.0625)] "
               "[--colours] [--check] -o DIR\n");
  return problem ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string tileset_path, out_dir;
  double frames_arg = 24, size_arg = 512, dots = 0.0625;
  bool check = false, colours = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--help" || a == "-h") {
      return usage(nullptr);
    } else if (a == "--check") {
      check = true;
    } else if (a == "--colours") {
      colours = true;
    } else if (!has_value && (a == "--tileset" || a == "-o" || a == "--frames" || a == "--size" ||
                              a == "--dots-per-pixel-area")) {
      return usage((a + " needs a value").c_str());
    } else if (a == "--tileset") {
      tileset_path = argv[++i];
    } else if (a == "-o") {
      out_dir = argv[++i];
    } else if (a == "--frames") {
      if (!parse_number(argv[++i], 2, 100000, frames_arg) || frames_arg != std::floor(frames_arg))
        return usage("--frames takes a whole number from 2 to 100000");
    } else if (a == "--size") {
      if (!parse_number(argv[++i], 32, 4096, size_arg) || size_arg != std::floor(size_arg))
        return usage("--size takes a whole number of pixels from 32 to 4096");
    } else if (a == "--dots-per-pixel-area") {
      if (!parse_number(argv[++i], 0.001, 1, dots))
        return usage("--dots-per-pixel-area takes a number from 0.001 to 1");
    } else {
      return usage(("unknown argument '" + a + "'").c_str());
    }
  }
  if (out_dir.empty()) return usage("-o DIR is required");
  const int frames = int(frames_arg), size = int(size_arg);
  kdm::Tileset loaded;
  if (!tileset_path.empty()) {
    std::string detail;
    const kdm::Status s = kdm::Tileset::load_file(tileset_path, loaded, &detail);
    if (s != kdm::Status::kOk)
      return std::fprintf(stderr, "texture_stipple: cannot load '%s': %s: %s\n", tileset_path.c_str(),
                          kdm::status_message(s), detail.c_str()),
             1;
  }
  const kdm::Tileset& tileset = tileset_path.empty() ? kdm::Tileset::builtin() : loaded;
  // The folder only once the inputs load: a refused run leaves nothing behind.
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec)
    return std::fprintf(stderr, "texture_stipple: cannot create '%s': %s\n", out_dir.c_str(),
                        ec.message().c_str()),
           1;

  // The path: straight down onto a point just beside a checker edge, the eye's distance to the surface
  // shrinking geometrically from 4 radii to 1/25 (the surface below 100× larger), so every frame zooms by
  // the same factor. The first frame shows the sphere 0.4 of the image across.
  const double target_u = 0.006, target_v = 0.1;
  const Vec dir = surface(target_u, target_v);
  auto altitude = [&](int k) { return 4 * std::pow(0.01, double(k) / (frames - 1)); };
  auto camera_at = [&](int k) { return Camera(dir, 1 + altitude(k), size); };

  // One tile size for every frame (another tile size is another tiling): the first frame's densest tile
  // expects a quarter of the set's top level, so the last, 10^4 times denser, lies past it.
  Frame frame{camera_at(0), dots, colours};
  const double top = tileset.max_points_per_tile();
  const double tile_size = std::sqrt(top / 4 / texture_density_bound(frame));
  std::printf("tile set: %g points per tile at its top level, density limit %g (smooth mode)\n", top,
              kdm::query_density_limit(tileset, kdm::QueryMode::kSmooth));
  // The fixed darkness whose dot density is compared across frames: the view centre's, ± 0.08.
  const double band_darkness = darkness(target_u, target_v, dir, colours), spacing = 1 / std::sqrt(dots),
               radius = 0.45 * spacing, fade = 0.2, subtiles = tileset.data().subtiles_per_side();
  std::printf("tile side %.4g texture units; fixed-tone band: darkness %.3f ± 0.08\n", tile_size,
              band_darkness);

  std::vector<kdm::QueryPoint> buffer(1 << 16);
  std::vector<std::uint8_t> inks(colours ? buffer.size() : 0);  // each point's class: its ink
  std::vector<Dot> previous, current;
  const int channels = colours ? 3 : 1;
  std::vector<unsigned char> image(std::size_t(size) * size * channels);
  double first_density = 0, last_density = 0, lowest = 1e9, highest = 0, worst_jump = 0, worst_rim = 0;
  double ink_lowest[kInks], ink_highest[kInks];  // with colours: each ink's dots on screen ÷ D × its cover
  std::fill(ink_lowest, ink_lowest + kInks, 1e9), std::fill(ink_highest, ink_highest + kInks, 0.0);
  unsigned deepest = 0;
  std::printf("frame  magnif.  points  shown depth  band dots/px² (÷ D·dark)  jump (rim)  query ms\n");
  for (int k = 0; k < frames; ++k) {
    frame.camera = camera_at(k);
    const Camera& cam = frame.camera;
    kdm::QueryParams q;
    visible_region(cam, q);
    q.tile_size = tile_size, q.scale = 1, q.mode = kdm::QueryMode::kSmooth;
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = texture_density, q.density.user = &frame;
    q.density.callback_max = texture_density_bound(frame);
    kdm::ClassQueryParams inked;  // with colours: the inks as classes, from one joint density
    if (colours) {
      inked.query = q, inked.class_count = kInks;
      inked.joint.densities = ink_densities, inked.joint.user = &frame;
      for (int c = 0; c < kInks; ++c) inked.joint.max[c] = full_density_bound(frame);
    }

    // The cursor loop into a caller-owned buffer, grown only when it fills up.
    const auto t0 = std::chrono::steady_clock::now();
    kdm::QueryCursor cursor;
    kdm::QueryProblem problem;
    std::size_t n = 0, total = 0;
    kdm::Status status;
    const auto run = [&] {
      return colours ? kdm::query_classes(tileset, inked, buffer.data() + total, inks.data() + total,
                                          buffer.size() - total, &n, &cursor, &problem)
                     : kdm::query_points(tileset, q, buffer.data() + total, buffer.size() - total, &n,
                                         &cursor, &problem);
    };
    while ((status = run()) == kdm::Status::kBufferFull) {
      total += n;
      if (total == buffer.size()) buffer.resize(2 * buffer.size()), inks.resize(colours ? buffer.size() : 0);
    }
    total += n;
    const double query_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (status != kdm::Status::kOk) {
      std::fflush(stdout);
      if (problem.kind == kdm::QueryProblem::Kind::kDensityTooHigh)  // a set without a hand-over
        std::fprintf(
            stderr,
            "texture_stipple: frame %d: the tile set serves at most %g points per tile, this frame needs "
            "%.0f: use a tile set with a hand-over to subtiles (--tileset)\n",
            k, problem.limit, problem.value);
      else {
        char why[256];
        kdm::describe_query_problem(problem, why, sizeof why);
        std::fprintf(stderr, "texture_stipple: frame %d: query refused: %s\n", k, why);
      }
      return 1;
    }

    // Draw the dots that face the camera and fall on screen; count those in the fixed-tone band.
    std::fill(image.begin(), image.end(), 255);
    current.clear();
    unsigned depth = 0;
    int shown = 0, band_dots = 0, ink_dots[kInks] = {};
    for (std::size_t i = 0; i < total; ++i) {
      const kdm::QueryPoint& p = buffer[i];
      const Vec s = surface(p.x, p.y);  // the origin is 0: positions are texture coordinates
      double sx, sy;
      cam.project(s, sx, sy);
      const bool visible = dot(cam.eye - s, s) > 0 && cam.on_screen(sx, sy);
      current.push_back({p.id, p.x, p.y, visible});
      depth = std::max(depth, p.id.depth);
      if (!visible) continue;
      ++shown;
      // The fade weight (docs/runtime.md, "Fading objects in"): the count of the point's (sub)tile at its
      // stable position, where the query reads it (not where the point has glided to), against the count
      // at which it appears.
      const double side = tile_size / std::pow(subtiles, p.id.depth);
      double ux = p.x, uy = p.y;
      kdm::stable_position(tileset, p.id, tile_size, 0, 0, &ux, &uy);
      const double count = texture_density(&frame, ux, uy) * q.scale * side * side;
      const double weight = std::clamp((count / kdm::emission_threshold(tileset, p.id) - 1) / fade, 0.0, 1.0);
      static constexpr unsigned char kBlack[3] = {0, 0, 0};
      if (weight > 0)
        draw_disc(image, size, channels, sx, sy, radius * std::sqrt(weight),
                  colours ? kInkRgb[inks[i]] : kBlack);
      if (std::abs(darkness(p.x, p.y, s, colours) - band_darkness) < 0.08) ++band_dots;
      if (colours) ++ink_dots[inks[i]];
    }
    deepest = std::max(deepest, depth);
    double band_area = 0, band_expected = 0;  // pixels of the band, and the dots they should hold
    double ink_expected[kInks] = {};          // with colours: the dots each ink should put on screen
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        Vec s;
        double u, v;
        if (!cam.cast(x + 0.5, y + 0.5, s)) continue;
        texture_coords(s, u, v);
        const double d = darkness(u, v, s, colours);
        if (std::abs(d - band_darkness) < 0.08) band_area += 1, band_expected += dots * d;
        if (!colours) continue;
        double cover[kInks];
        ink_cover(u, v, s, cover);
        for (int c = 0; c < kInks; ++c) ink_expected[c] += dots * cover[c];
      }
    const double density = band_area > 0 ? band_dots / band_area : 0;
    const double relative = band_expected > 0 ? band_dots / band_expected : 0;
    if (k == 0) first_density = relative;
    for (int c = 0; c < (colours ? kInks : 0); ++c) {
      if (ink_expected[c] < 100) continue;  // too few to judge
      const double share = ink_dots[c] / ink_expected[c];
      ink_lowest[c] = std::min(ink_lowest[c], share), ink_highest[c] = std::max(ink_highest[c], share);
    }
    last_density = relative, lowest = std::min(lowest, relative), highest = std::max(highest, relative);

    // Dots in both frames, matched by id: how far each moved over the surface, in its own spacing along
    // the way it moved, seen by this frame's camera (so the camera's own motion is not counted). Near a
    // point the projection is linear, so that ratio is the texture-space step over the texture-space
    // spacing 1/√density there, whatever the foreshortening stretches on screen.
    std::sort(current.begin(), current.end(), id_less);
    double jump = 0, rim_jump = 0;
    for (std::size_t i = 0, j = 0; k > 0 && i < current.size(); ++i) {
      while (j < previous.size() && id_less(previous[j], current[i])) ++j;
      if (j == previous.size() || id_less(current[i], previous[j]) || !current[i].shown || !previous[j].shown)
        continue;
      const Vec a = surface(previous[j].u, previous[j].v), b = surface(current[i].u, current[i].v);
      const double moved = std::hypot(current[i].u - previous[j].u, current[i].v - previous[j].v) *
                           std::sqrt(texture_density(&frame, current[i].u, current[i].v));
      // Near the silhouette the texture-space density falls to 0 with the foreshortening, so the few points
      // there lie far apart in texture space and glide fast as the silhouette sweeps over them: kept apart.
      const bool rim = std::min(dot(normalized(cam.eye - a), a), dot(normalized(cam.eye - b), b)) < kRim;
      double& largest = rim ? rim_jump : jump;
      largest = std::max(largest, moved);
    }
    worst_jump = std::max(worst_jump, jump), worst_rim = std::max(worst_rim, rim_jump);
    std::swap(previous, current);

    std::printf("%5d %8.2f %7zu %6d %5u %12.5f (%5.3f) %6.3f (%5.2f) %8.2f\n", k, altitude(0) / altitude(k),
                total, shown, depth, density, relative, jump, rim_jump, query_ms);
    char name[64];
    std::snprintf(name, sizeof name, "/frame_%03d.png", k);
    const std::string path = out_dir + name;
    if (!stbi_write_png(path.c_str(), size, size, channels, image.data(), size * channels))
      return std::fprintf(stderr, "texture_stipple: cannot write '%s'\n", path.c_str()), 1;
  }
  const double drift = last_density / first_density - 1;
  std::printf("band density ÷ D·darkness: %.3f to %.3f; closest ÷ farthest frame %.3f (%+.1f%%)\n", lowest,
              highest, last_density / first_density, 100 * drift);
  std::printf("largest jump %.3f spacings (%.2f near the silhouette); deepest depth %u\n", worst_jump,
              worst_rim, deepest);
  bool inks_follow = true;
  for (int c = 0; c < (colours ? kInks : 0); ++c) {
    std::printf("%s dots on screen ÷ D·cover: %.3f to %.3f\n", kInkNames[c], ink_lowest[c], ink_highest[c]);
    inks_follow = inks_follow && ink_lowest[c] >= 0.9 && ink_highest[c] <= 1.1;
  }
  std::fflush(stdout);  // before any message on stderr
  if (check && (!(std::abs(drift) <= 0.10) || !(worst_jump < 0.5) || !inks_follow)) {
    std::fprintf(stderr, "texture_stipple: check failed:%s%s%s\n",
                 std::abs(drift) <= 0.10 ? "" : " the band's dot density drifts by more than 10%;",
                 worst_jump < 0.5
                     ? ""
                     : " a dot moved half a spacing or more in one frame (the fewer the frames, the "
                       "farther dots move: the 100x zoom needs about 300 to pass, --frames 300);",
                 inks_follow ? "" : " an ink's dots on screen are more than 10% off its cover");
    return 1;
  }
  return 0;
}
