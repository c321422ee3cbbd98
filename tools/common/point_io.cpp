#include "point_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "image_io.h"

namespace kdm::tools {

bool has_extension(const std::string& path, const char* extension) {
  const std::size_t n = std::strlen(extension);
  if (path.size() < n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(path[path.size() - n + i])) !=
        std::tolower(static_cast<unsigned char>(extension[i])))
      return false;
  return true;
}

std::string output_format(const std::string& path, const std::string& format) {
  std::string ext = format;
  if (ext.empty()) {
    const std::size_t dot = path.find_last_of('.'), slash = path.find_last_of('/');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ext = path.substr(dot);
  } else if (ext[0] != '.') {
    ext = "." + ext;
  }
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool check_output_path(const std::string& path, const std::vector<const char*>& extensions,
                       std::string& error, const std::string& format) {
  const std::string ext = output_format(path, format);
  bool known = false;
  std::string list, names;
  for (std::size_t i = 0; i < extensions.size(); ++i) {
    known = known || ext == extensions[i];
    const char* sep = i == 0 ? "" : i + 1 == extensions.size() ? " or " : ", ";
    list += sep + std::string(extensions[i]);
    names += sep + std::string(extensions[i] + 1);
  }
  if (path == kStandardOutput && format.empty()) {
    error = "'-' (standard output) needs --format: " + names;
    return false;
  }
  if (!known) {
    error = format.empty() ? "unknown output format for '" + path + "' (use " + list + ")"
                           : "unknown --format '" + format + "' (use " + names + ")";
    return false;
  }
  if (path == kStandardOutput) return true;
  // A file named for another format than --format gives it: its viewer would misread it.
  const std::string named = output_format(path);
  if (!format.empty() && named != ext)
    for (const char* other : {".txt", ".csv", ".json", ".svg", ".png"})
      if (named == other) {
        error = "--format " + ext.substr(1) + " would write " + ext.substr(1) + " into '" + path + "', a " +
                named.substr(1) + " file name: name the file ." + ext.substr(1);
        return false;
      }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error = "output '" + path + "' is a directory";
    return false;
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
    error = "cannot write '" + path + "': directory '" + dir.string() + "' does not exist";
    return false;
  }
  return true;
}

std::string comment_safe(std::string line) {
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  for (std::size_t at = line.find("--"); at != std::string::npos; at = line.find("--", at + 2))
    line.insert(at + 1, " ");
  return line;
}

bool read_point_sets(const std::string& path, std::vector<PointSet>& sets, std::string& error) {
  if (path == "-") return read_point_sets(std::cin, "standard input", sets, error);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    error = "point file '" + path + "' is a directory";
    return false;
  }
  std::ifstream in(path);
  if (!in) {
    error = "cannot open point file '" + path + "'";
    return false;
  }
  return read_point_sets(in, path, sets, error);
}

namespace {

/// The longest line a point file may have: seven numbers of 17 digits with room to spare. A file that
/// never ends a line (a binary file, /dev/zero) is refused there instead of read whole.
constexpr std::size_t kMaxLineLength = 4096;

/// Reads one line into `line` (without its '\n'). False at the end of `in`, or when the line is longer
/// than kMaxLineLength (`too_long` set).
bool read_line(std::istream& in, std::string& line, bool& too_long) {
  line.clear();
  std::streambuf* buffer = in.rdbuf();
  for (int c = buffer->sbumpc(); c != std::char_traits<char>::eof(); c = buffer->sbumpc()) {
    if (c == '\n') return true;
    if (line.size() == kMaxLineLength) return !(too_long = true);
    line.push_back(static_cast<char>(c));
  }
  return !line.empty();
}

/// The start of `line` for an error message: at most 40 characters, bytes that are not printable ASCII as
/// \xNN.
std::string excerpt(const std::string& line) {
  std::string out;
  for (std::size_t i = 0; i < line.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(line[i]);
    if (c >= 0x20 && c < 0x7f) {
      out.push_back(static_cast<char>(c));
    } else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return line.size() > 40 ? out + "..." : out;
}

}  // namespace

bool read_point_sets(std::istream& in, const std::string& path, std::vector<PointSet>& sets,
                     std::string& error) {
  sets.clear();
  PointSet current;
  int file_dim = 0;
  std::string line;
  int line_no = 0;
  // Columns of a labelled CSV: which hold x, y and the class, and how many a line has.
  int columns = 0, class_column = -1;
  auto finish_set = [&] {
    if (!current.coords.empty()) sets.push_back(current);
    current.coords.clear(), current.classes.clear();
  };
  bool too_long = false;
  while (read_line(in, line, too_long)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      finish_set();
      continue;
    }
    // The CSV files write_point_set produces start with a column header: skip it so they read back.
    if (line_no == 1) {
      std::string head = line.substr(first);
      while (!head.empty() && (head.back() == '\r' || head.back() == ' ')) head.pop_back();
      if (head == "x,y" || head == "x,y,z") continue;
      if (head == "x,y,class") {
        columns = 3, class_column = 2;
        continue;
      }
      // kdm query's, with a depth column since 0.5 (earlier files have none).
      // kdm query's: the class (several classes) and the depth (since 0.5) after the six columns.
      if (head.rfind("x,y,tile_x,tile_y,rank,level", 0) == 0) {
        const std::string rest = head.substr(28);
        if (rest.empty() || rest == ",class" || rest == ",depth" || rest == ",class,depth") {
          columns = 6 + int(std::count(rest.begin(), rest.end(), ','));
          class_column = rest.rfind(",class", 0) == 0 ? 6 : -1;
          continue;
        }
      }
    }
    std::vector<double> values;
    // To the line's end, not its first NUL: a NUL byte is malformed, not the end of the line.
    const char* p = line.c_str() + first;
    const char* const line_end = line.c_str() + line.size();
    while (p < line_end) {
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end == p) {
        error = path + ":" + std::to_string(line_no) + ": malformed number in '" + excerpt(line) + "'";
        return false;
      }
      if (!std::isfinite(v)) {
        const bool a_class = class_column >= 0 && static_cast<int>(values.size()) == class_column;
        error = path + ":" + std::to_string(line_no) +
                (a_class ? ": a class must be an integer 0 to 255" : ": non-finite coordinate");
        return false;
      }
      values.push_back(v);
      p = end;
      while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') ++p;
    }
    if (columns) {  // a labelled or query CSV: x, y and the class
      if (static_cast<int>(values.size()) != columns) {
        error = path + ":" + std::to_string(line_no) + ": expected " + std::to_string(columns) +
                " columns, found " + std::to_string(values.size());
        return false;
      }
      if (class_column >= 0) {
        const double c = values[class_column];
        if (!(c >= 0 && c <= 255 && c == std::floor(c))) {
          error = path + ":" + std::to_string(line_no) + ": a class must be an integer 0 to 255";
          return false;
        }
        current.classes.push_back(static_cast<std::uint8_t>(c));
      }
      values.resize(2);
    }
    const int dim = static_cast<int>(values.size());
    if (dim != 2 && dim != 3) {
      error = path + ":" + std::to_string(line_no) + ": expected 2 or 3 coordinates, found " +
              std::to_string(dim);
      return false;
    }
    if (file_dim == 0) file_dim = dim;
    if (dim != file_dim) {
      error = path + ":" + std::to_string(line_no) + ": dimension changes from " + std::to_string(file_dim) +
              " to " + std::to_string(dim);
      return false;
    }
    current.dim = dim;
    current.coords.insert(current.coords.end(), values.begin(), values.end());
  }
  if (too_long) {
    error = path + ":" + std::to_string(line_no + 1) + ": a line longer than " +
            std::to_string(kMaxLineLength) + " characters: not a point file";
    return false;
  }
  finish_set();
  if (sets.empty()) {
    error = "point file '" + path + "' holds no points";
    return false;
  }
  return true;
}

bool write_point_set(const std::string& path, const PointSet& set, const std::vector<std::string>& header,
                     std::string& error, const std::string& format) {
  const bool csv = output_format(path, format) == ".csv";
  const bool labelled = !set.classes.empty();
  if (labelled && (!csv || set.dim != 2 || set.classes.size() != set.size())) {
    error = "'" + path + "': " +
            (set.dim != 2 ? std::string("points with classes are 2D only")
                          : "points with classes are written as .csv (x,y,class)");
    return false;
  }
  // One string grown once, numbers by to_chars (printf's %.17g, as `ostream << double` at precision 17
  // wrote them): at 262,144 points a string stream doubling its buffer took a third of the page faults of
  // a whole `kdm sample` run on our VM.
  std::string out;
  out.reserve(64 + header.size() * 80 + set.coords.size() * 25);
  if (csv) {
    out += set.dim == 3 ? "x,y,z\n" : labelled ? "x,y,class\n" : "x,y\n";
  } else {
    for (const std::string& h : header) out += "# " + comment_safe(h) + '\n';
  }
  const char sep = csv ? ',' : ' ';
  char number[32];
  for (std::size_t i = 0; i < set.size(); ++i) {
    for (int k = 0; k < set.dim; ++k) {
      if (k) out += sep;
      const auto written = std::to_chars(number, number + sizeof number, set.coords[i * set.dim + k],
                                         std::chars_format::general, 17);
      out.append(number, written.ptr);
    }
    if (labelled) out += ',' + std::to_string(set.classes[i]);
    out += '\n';
  }
  return write_text_file_atomic(path, out, error);
}

}  // namespace kdm::tools
