#include "image_io.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

namespace kdm::tools {
namespace {

std::string temp_path_for(const std::string& path) {
  return path + ".tmp~";
}

bool commit_temp(const std::string& tmp, const std::string& path, std::string& error) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace

bool load_grey_image(const std::string& path, GreyImage& out, std::string& error) {
  int w = 0, h = 0, channels = 0;
  const bool sixteen = stbi_is_16_bit(path.c_str()) != 0;
  std::vector<float> values;
  if (sixteen) {
    std::unique_ptr<stbi_us, void (*)(void*)> data(stbi_load_16(path.c_str(), &w, &h, &channels, 0),
                                                   stbi_image_free);
    if (!data) {
      error = "cannot read image '" + path + "': " + stbi_failure_reason();
      return false;
    }
    values.assign(data.get(), data.get() + static_cast<std::size_t>(w) * h * channels);
    for (float& v : values) v /= 65535.0f;
  } else {
    std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &channels, 0),
                                                   stbi_image_free);
    if (!data) {
      const char* reason = stbi_failure_reason();
      error = "cannot read image '" + path + "': " + (reason ? reason : "unknown format");
      return false;
    }
    values.assign(data.get(), data.get() + static_cast<std::size_t>(w) * h * channels);
    for (float& v : values) v /= 255.0f;
  }
  if (w <= 0 || h <= 0) {
    error = "image '" + path + "' is empty";
    return false;
  }
  out.width = w;
  out.height = h;
  out.pixels.resize(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < out.pixels.size(); ++i) {
    const float* p = &values[i * channels];
    float lum = 0, alpha = 1;
    switch (channels) {
      case 1:
        lum = p[0];
        break;
      case 2:
        lum = p[0];
        alpha = p[1];
        break;
      case 3:
        lum = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        break;
      default:
        lum = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        alpha = p[3];
        break;
    }
    out.pixels[i] = std::clamp(lum * alpha + (1.0f - alpha), 0.0f, 1.0f);  // composite on white paper
  }
  return true;
}

bool write_png(const std::string& path, const RgbImage& image, std::string& error) {
  if (image.width <= 0 || image.height <= 0) {
    error = "cannot write an empty image to '" + path + "'";
    return false;
  }
  const std::string tmp = temp_path_for(path);
  if (!stbi_write_png(tmp.c_str(), image.width, image.height, 3, image.pixels.data(), image.width * 3)) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return commit_temp(tmp, path, error);
}

void draw_disc(RgbImage& image, double cx, double cy, double r, const std::uint8_t rgb[3]) {
  // Coverage by distance to the edge, one pixel of antialiasing ramp.
  const int x0 = std::max(0, static_cast<int>(std::floor(cx - r - 1)));
  const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(cx + r + 1)));
  const int y0 = std::max(0, static_cast<int>(std::floor(cy - r - 1)));
  const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(cy + r + 1)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double coverage = std::clamp(r + 0.5 - d, 0.0, 1.0);
      if (coverage <= 0) continue;
      std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 3];
      for (int c = 0; c < 3; ++c)
        p[c] = static_cast<std::uint8_t>(std::lround(p[c] + (rgb[c] - p[c]) * coverage));
    }
  }
}

bool write_text_file_atomic(const std::string& path, const std::string& text, std::string& error) {
  const std::string tmp = temp_path_for(path);
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f || !(f << text) || !f.flush()) {
      error = "cannot write '" + path + "': " + std::strerror(errno);
      std::remove(tmp.c_str());
      return false;
    }
  }
  return commit_temp(tmp, path, error);
}

}  // namespace kdm::tools
