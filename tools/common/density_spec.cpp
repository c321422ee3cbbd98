// Parsing densities as users name them (density_spec.h).
#include "density_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "image_io.h"
#include "point_io.h"

namespace kdm::tools {

double DensitySpec::map_at(double u, double v) const {
  const double a = std::log(range);
  if (kind == Kind::kRamp) return std::exp(-a * u);
  if (kind == Kind::kRadial) {
    const double dx = u - 0.5, dy = v - 0.5;
    return std::exp(-a * std::min(1.0, 2 * std::sqrt(dx * dx + dy * dy)));
  }
  return 1;
}

double DensitySpec::max_value() const {
  if (kind == Kind::kConstant) return constant;
  if (kind == Kind::kImage || kind == Kind::kVolume)
    return values.empty() ? 0.0 : double(*std::max_element(values.begin(), values.end()));
  return 1;
}

double DensitySpec::mean_value() const {
  switch (kind) {
    case Kind::kConstant:
      return constant;
    case Kind::kImage:
    case Kind::kVolume: {
      double sum = 0;
      for (float v : values) sum += v;
      return values.empty() ? 0.0 : sum / double(values.size());
    }
    case Kind::kRamp:  // ∫₀¹ R^-u du
      return range > 1 ? (1 - 1 / range) / std::log(range) : 1.0;
    case Kind::kRadial: {  // the disc r < 1/2 by the radial integral, 1/R outside it
      const double a = std::log(range);
      if (!(a > 0)) return 1.0;
      // ∫₀^½ e^(−2ar) 2πr dr = (π / (2a²)) (1 − e^(−a)(1 + a))
      const double disc = std::acos(-1.0) / (2 * a * a) * (1 - std::exp(-a) * (1 + a));
      return disc + (1 - std::acos(-1.0) / 4) / range;
    }
  }
  return 1;
}

double picture_tone(double grey, double alpha, bool invert) {
  const double tone = invert ? grey - (1.0 - alpha) : 1.0 - grey;
  // Float rounding of the composited grey leaves tones of about 1e-7 where the exact tone is 0 (black at
  // part opacity, inverted): noise, not ink, far below a 16-bit level's step of 1.5e-5.
  constexpr double kToneNoise = 1.0 / (1 << 20);
  return tone < kToneNoise ? 0.0 : tone;
}

namespace {

/// A finite number that fills `text` exactly, or NaN.
double parse_number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0' && std::isfinite(v) ? v : std::nan("");
}

/// Bytes in memory as a seekable stream buffer (read_npy_density seeks back to read the data twice).
class MemoryBuffer : public std::streambuf {
 public:
  MemoryBuffer(const char* data, std::size_t size) {
    char* begin = const_cast<char*>(data);  // only ever read
    setg(begin, begin, begin + size);
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    const off_type from = dir == std::ios_base::beg   ? 0
                          : dir == std::ios_base::cur ? gptr() - eback()
                                                      : egptr() - eback();
    if (off < -from || off > (egptr() - eback()) - from) return pos_type(off_type(-1));
    setg(eback(), eback() + from + off, egptr());
    return pos_type(from + off);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

/// A picture's densities: its tone (picture_tone) to the power `gamma`, row 0 at the bottom.
DensitySpec image_density(const GreyImage& image, const std::string& text, double gamma, bool invert);

/// A NumPy array of densities: 2-D as a kImage spec, 3-D as a kVolume one (parse_density_spec says which);
/// throws naming the file and the problem: std::runtime_error for a file it cannot read (a header it
/// cannot parse, data cut short), std::invalid_argument for an array that is no density (its type, shape
/// or values), as for the same array given in memory.
DensitySpec read_npy_density(const std::string& path, std::istream& in) {
  auto fail = [&](const std::string& what) {
    return std::runtime_error("density '" + path + "': NumPy .npy file: " + what);
  };
  auto bad = [&](const std::string& what) {
    return std::invalid_argument("density '" + path + "': NumPy .npy file: " + what);
  };
  std::streambuf& buffer = *in.rdbuf();
  char magic[6];
  buffer.sgetn(magic, 6);
  NpyHeader h;
  std::string what;
  if (!read_npy_header(buffer, h, what)) throw fail(what);
  // Reals as numpy writes them, in either byte order: float16/32/64, (u)int8 to 64, bool.
  NpyScalar type;
  if (!parse_npy_scalar(h.descr, type))
    throw bad("data of type '" + h.descr +
              "': expected real numbers (float16, 32 or 64, integers of 8 to 64 bits, bool; either byte "
              "order)");
  const std::size_t bytes = type.bytes;
  std::string dims;
  for (std::size_t i = 0; i < h.shape.size(); ++i) dims += (i ? ", " : "") + std::to_string(h.shape[i]);
  if (h.shape.size() != 2 && h.shape.size() != 3)
    throw bad("an array of shape (" + dims +
              "): expected a 2-D array (rows, columns) or, for --dim 3, a 3-D one (depth, height, width)");
  const bool flat = h.shape.size() == 2;  // a picture's densities: one slice
  const std::uint64_t d = flat ? 1 : h.shape[0], rows = h.shape[flat ? 0 : 1], cols = h.shape[flat ? 1 : 2];
  if (d == 0 || rows == 0 || cols == 0) throw bad("an empty array of shape (" + dims + ")");
  if (d > kMaxImagePixels || rows > kMaxImagePixels || cols > kMaxImagePixels ||
      d * rows * cols > kMaxImagePixels)
    throw bad("an array of shape (" + dims + "): more than 2^26 values (the image size limit)");
  DensitySpec spec;
  spec.kind = flat ? DensitySpec::Kind::kImage : DensitySpec::Kind::kVolume;
  spec.array = true;
  spec.text = path;
  spec.width = static_cast<int>(cols), spec.height = static_cast<int>(rows);
  if (!flat) spec.depth = static_cast<int>(d);
  const std::uint64_t count = d * rows * cols;
  spec.values.resize(static_cast<std::size_t>(count));
  // Calls f(value, index into spec.values) for every element from the data's start, in file order.
  const std::streampos data = buffer.pubseekoff(0, std::ios::cur, std::ios::in);
  auto each = [&](auto f) {
    if (buffer.pubseekpos(data, std::ios::in) != data) throw fail("cannot read its data");
    unsigned char chunk[1 << 14];
    for (std::uint64_t done = 0; done < count;) {
      const std::uint64_t n = std::min<std::uint64_t>(count - done, sizeof chunk / bytes);
      if (static_cast<std::uint64_t>(buffer.sgetn(reinterpret_cast<char*>(chunk),
                                                  static_cast<std::streamsize>(n * bytes))) != n * bytes)
        throw fail("cut short: its header promises " + std::to_string(count) + " values");
      for (std::uint64_t k = 0; k < n; ++k) {
        // The element's numpy index [slice, row, column], in either order.
        const std::uint64_t at = done + k;
        std::uint64_t z, row, col;
        if (h.fortran)
          z = at % d, row = at / d % rows, col = at / (d * rows);
        else
          col = at % cols, row = at / cols % rows, z = at / (cols * rows);
        const double v = npy_scalar_value(chunk + k * bytes, type);
        if (!(std::isfinite(v) && v >= 0))
          throw bad("a value of " + std::to_string(v) + " at [" + (flat ? "" : std::to_string(z) + ", ") +
                    std::to_string(row) + ", " + std::to_string(col) +
                    "]: densities must be finite and >= 0");
        // Rows are stored top first, as in a picture; kdm keeps row 0 at the bottom.
        f(v, static_cast<std::size_t>((z * rows + (rows - 1 - row)) * cols + col));
      }
      done += n;
    }
  };
  double top = 0;
  each([&](double v, std::size_t) { top = std::max(top, v); });
  // Only the shape matters: values whose largest is outside the sampler's range (1e-30 ... 1e30) are divided
  // by it in float64 before they become floats, as kdm.sample does with an array (the same bits).
  const double divisor = top > 0 && !(top >= 1e-30 && top <= 1e30) ? top : 1;
  each([&](double v, std::size_t i) { spec.values[i] = static_cast<float>(v / divisor); });
  spec.divided_by = divisor;
  return spec;
}

}  // namespace

DensitySpec parse_density_spec(const std::string& text, double gamma, bool invert, std::uint64_t max_pixels,
                               const KeptPixels& kept, double white) {
  DensitySpec spec;
  spec.text = text;
  if (!(std::isfinite(gamma) && gamma > 0)) throw std::invalid_argument("gamma must be a finite number > 0");
  if (text.rfind("const:", 0) == 0) {
    const double v = parse_number(text.substr(6));
    if (!(v >= 0))
      throw std::invalid_argument("density const:V needs a finite V >= 0, got '" + text.substr(6) + "'");
    spec.constant = v;
    return spec;
  }
  for (const char* kind : {"ramp:", "radial:"}) {
    const std::size_t len = std::char_traits<char>::length(kind);
    if (text.compare(0, len, kind) != 0) continue;
    const double range = parse_number(text.substr(len));
    if (!(range >= 1 && range <= 1e9))
      throw std::invalid_argument("density " + std::string(kind) +
                                  "R needs a dynamic range R in [1, 1e9], got '" + text.substr(len) + "'");
    spec.kind = len == 5 ? DensitySpec::Kind::kRamp : DensitySpec::Kind::kRadial;
    spec.range = range;
    return spec;
  }
  std::error_code missing;
  if (!std::filesystem::exists(text, missing))  // a misspelt map more often than a missing picture
    throw std::runtime_error(
        "density '" + text +
        "': no such file (a density is a picture, const:V, ramp:R, radial:R or a .npy array)");
  if (std::filesystem::is_regular_file(text, missing)) {  // a directory is refused by the image loader
    std::ifstream file(text, std::ios::binary);
    char magic[6] = {};
    if (file && file.rdbuf()->sgetn(magic, 6) == 6 && std::memcmp(magic, "\x93NUMPY", 6) == 0) {
      if (gamma != 1 || invert)  // they reshape a picture's tones; a volume holds densities
        throw std::invalid_argument(
            "density '" + text +
            "' is a NumPy array of densities: --gamma and --invert apply to images only");
      file.seekg(0);
      return read_npy_density(text, file);
    }
  }
  GreyImage image;
  std::string error;
  if (!load_grey_image(text, image, error, max_pixels, kept, white)) throw std::runtime_error(error);
  return image_density(image, text, gamma, invert);
}

DensitySpec parse_density_bytes(const void* data, std::size_t size, const std::string& name, double gamma,
                                bool invert, std::uint64_t max_pixels, const KeptPixels& kept, double white) {
  if (!(std::isfinite(gamma) && gamma > 0)) throw std::invalid_argument("gamma must be a finite number > 0");
  if (size >= 6 && std::memcmp(data, "\x93NUMPY", 6) == 0) {
    if (gamma != 1 || invert)
      throw std::invalid_argument(
          "density '" + name + "' is a NumPy array of densities: --gamma and --invert apply to images only");
    MemoryBuffer buffer(static_cast<const char*>(data), size);
    std::istream in(&buffer);
    return read_npy_density(name, in);
  }
  GreyImage image;
  std::string error;
  if (!load_grey_image_memory(data, size, image, error, name, max_pixels, kept, white))
    throw std::runtime_error(error);
  return image_density(image, name, gamma, invert);
}

namespace {

DensitySpec image_density(const GreyImage& image, const std::string& text, double gamma, bool invert) {
  DensitySpec spec;
  spec.text = text;
  // Densities keep row 0 at the bottom (y up); the picture's row 0 is its top: flipped here, once.
  spec.kind = DensitySpec::Kind::kImage;
  spec.width = image.width, spec.height = image.height, spec.inverted = invert;
  spec.values.resize(image.pixels.size());
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const int row = image.height - 1 - y;
      const double alpha = image.alpha.empty() ? 1.0 : image.alpha[std::size_t(row) * image.width + x];
      spec.values[static_cast<std::size_t>(y) * image.width + x] =
          static_cast<float>(std::pow(picture_tone(image.at(x, row), alpha, invert), gamma));
    }
  return spec;
}

}  // namespace

std::pair<int, int> images_of_different_shapes(const std::vector<const DensitySpec*>& specs) {
  int first = -1;
  for (int k = 0; k < static_cast<int>(specs.size()); ++k) {
    const DensitySpec& s = *specs[k];
    if (s.kind != DensitySpec::Kind::kImage) continue;
    if (first < 0) {
      first = k;
      continue;
    }
    const DensitySpec& f = *specs[first];
    const double a = double(s.width) * f.height, b = double(f.width) * s.height;  // ratios times heights
    if (std::fabs(a - b) > 0.01 * b) return {first, k};
  }
  return {-1, -1};
}

}  // namespace kdm::tools
