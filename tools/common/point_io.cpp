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

#include "atomic_file.h"

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

std::string extension_list(const std::vector<const char*>& extensions) {
  std::string list;
  for (std::size_t i = 0; i < extensions.size(); ++i)
    list += (i == 0 ? "" : i + 1 == extensions.size() ? " or " : ", ") + std::string(extensions[i]);
  return list;
}

bool check_output_path(const std::string& path, const std::vector<const char*>& extensions,
                       std::string& error, const std::string& format) {
  const std::string ext = output_format(path, format);
  bool known = false;
  const std::string list = extension_list(extensions);
  std::string names;
  for (std::size_t i = 0; i < extensions.size(); ++i) {
    known = known || ext == extensions[i];
    names += (i == 0 ? "" : i + 1 == extensions.size() ? " or " : ", ") + std::string(extensions[i] + 1);
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
    for (const char* other : {".txt", ".csv", ".npy", ".json", ".svg", ".png"})
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

namespace {

/// What a header line names: how many columns a row has, and which hold x, y, z and the class (-1: none).
struct Header {
  int columns = 0, x = -1, y = -1, z = -1, label = -1;
};

/// `line` cut into fields at commas (not those inside double quotes, as CSV writers quote them), or where
/// it has none at blanks and tabs; each trimmed of blanks, '\r' and enclosing quotes.
std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  const bool commas = line.find(',') != std::string::npos;
  std::size_t at = 0;
  while (at <= line.size()) {
    std::size_t end = at;
    if (commas) {
      for (bool quoted = false; end < line.size() && (quoted || line[end] != ','); ++end)
        if (line[end] == '"') quoted = !quoted;
    } else {
      end = line.find_first_of(" \t", at);
    }
    if (end == std::string::npos) end = line.size();
    std::string f = line.substr(at, end - at);
    const std::size_t a = f.find_first_not_of(" \t\r"), b = f.find_last_not_of(" \t\r");
    f = a == std::string::npos ? "" : f.substr(a, b - a + 1);
    if (f.size() >= 2 && (f.front() == '"' || f.front() == '\'') && f.back() == f.front())
      f = f.substr(1, f.size() - 2);
    if (commas || !f.empty()) fields.push_back(f);
    at = end + 1;
  }
  return fields;
}

/// Whether `field` is a whole number such as strtod reads ("0.5", "nan", "inf"), blanks around it allowed.
bool parse_number(const std::string& field, double& v) {
  const char* p = field.c_str();
  char* end = nullptr;
  v = std::strtod(p, &end);
  if (end == p) return false;
  while (*end == ' ' || *end == '\t' || *end == '\r') ++end;
  return end == p + field.size();
}

/// Whether a first line is a column header: printable text whose every field is a name (it starts with a
/// letter or '_' and is no number such as "nan") or empty (pandas' unnamed index column, a trailing
/// comma), at least one a name; not a row of numbers or a binary file's first bytes.
bool is_header(const std::string& head) {
  for (char c : head)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r') return false;
  bool named = false;
  for (const std::string& f : split_fields(head)) {
    double v;
    if (f.empty()) continue;
    if (parse_number(f, v)) return false;
    const unsigned char c = static_cast<unsigned char>(f[0]);
    if (!std::isalpha(c) && c != '_') return false;
    named = true;
  }
  return named;
}

/// Reads a header's columns: x and y (and z, and the class as "class" or "label") by name, trimmed and in
/// any case, in any order; other columns are skipped. False with `error` (no file or line) if it names
/// no x or y, or a column twice.
bool parse_header(const std::string& head, Header& h, std::string& error) {
  const std::vector<std::string> fields = split_fields(head);
  h.columns = static_cast<int>(fields.size());
  for (int i = 0; i < h.columns; ++i) {
    std::string name = fields[i];
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    int* column = name == "x"                          ? &h.x
                  : name == "y"                        ? &h.y
                  : name == "z"                        ? &h.z
                  : name == "class" || name == "label" ? &h.label
                                                       : nullptr;
    if (!column) continue;
    if (*column >= 0) {
      error = "header '" + excerpt(head) + "' names " +
              (column == &h.label ? std::string("the class twice (class and label are one column)")
                                  : "column " + name + " twice");
      return false;
    }
    *column = i;
  }
  if (h.x < 0 || h.y < 0) {
    error =
        "header '" + excerpt(head) + "': expected columns named x and y (and z, class)" +
        (head.find(';') != std::string::npos ? ", separated by commas, or by blanks and tabs, not semicolons"
                                             : "");
    return false;
  }
  if (h.z >= 0 && h.label >= 0) {
    error = "header '" + excerpt(head) + "': classes are for 2D points, and z makes them 3D";
    return false;
  }
  return true;
}

}  // namespace

bool read_npy_header(std::streambuf& in, NpyHeader& out, std::string& what) {
  auto fail = [&](const std::string& problem) {
    what = problem;
    return false;
  };
  std::streambuf* buffer = &in;
  auto read = [&](void* to, std::size_t n) {
    return static_cast<std::size_t>(buffer->sgetn(static_cast<char*>(to), static_cast<std::streamsize>(n))) ==
           n;
  };
  unsigned char pre[12];  // the magic (already read), the version, the header's length
  if (!read(pre + 6, 2)) return fail("cut short in its header");
  if (pre[6] < 1 || pre[6] > 3) return fail("unknown format version " + std::to_string(pre[6]));
  const std::size_t length_bytes = pre[6] == 1 ? 2 : 4;
  if (!read(pre + 8, length_bytes)) return fail("cut short in its header");
  std::size_t header_length = 0;
  for (std::size_t i = length_bytes; i-- > 0;) header_length = header_length << 8 | pre[8 + i];
  constexpr std::size_t kMaxHeader = 1 << 16;  // np.save writes about 128 bytes
  if (header_length > kMaxHeader)
    return fail("a header of " + std::to_string(header_length) + " bytes (at most 65536)");
  std::string header(header_length, '\0');
  if (!read(header.data(), header_length)) return fail("cut short in its header");
  // The header is a Python dict literal: {'descr': '<f8', 'fortran_order': False, 'shape': (n, 2), }
  std::size_t at = 0;
  auto skip = [&] {
    while (at < header.size() && std::isspace(static_cast<unsigned char>(header[at]))) ++at;
  };
  auto take = [&](char c) {
    skip();
    if (at < header.size() && header[at] == c) return ++at, true;
    return false;
  };
  auto quoted = [&](std::string& s) {
    skip();
    if (at >= header.size() || (header[at] != '\'' && header[at] != '"')) return false;
    const std::size_t end = header.find(header[at], at + 1);
    if (end == std::string::npos) return false;
    s = header.substr(at + 1, end - at - 1), at = end + 1;
    return true;
  };
  std::string descr;
  int fortran = -1;
  std::vector<std::uint64_t>& shape = out.shape;
  shape.clear();
  bool has_shape = false;
  if (!take('{')) return fail("a header that is no dictionary");
  while (!take('}')) {
    std::string key;
    if (!quoted(key) || !take(':')) return fail("a malformed header");
    skip();
    if (key == "descr") {
      if (!quoted(descr)) return fail("a malformed 'descr'");
    } else if (key == "fortran_order") {
      if (header.compare(at, 4, "True") == 0)
        fortran = 1, at += 4;
      else if (header.compare(at, 5, "False") == 0)
        fortran = 0, at += 5;
      else
        return fail("a malformed 'fortran_order'");
    } else if (key == "shape") {
      if (!take('(')) return fail("a malformed 'shape'");
      while (!take(')')) {
        skip();
        std::uint64_t v = 0;
        const std::size_t from = at;
        while (at < header.size() && std::isdigit(static_cast<unsigned char>(header[at])) && v < (1ull << 40))
          v = v * 10 + static_cast<std::uint64_t>(header[at++] - '0');
        if (at == from || v >= (1ull << 40) || shape.size() == 8) return fail("a malformed 'shape'");
        shape.push_back(v);
        if (!take(',') && (skip(), at >= header.size() || header[at] != ')'))
          return fail("a malformed 'shape'");
      }
      has_shape = true;
    } else {
      return fail("an unknown header key '" + excerpt(key) + "'");
    }
    if (!take(',') && (skip(), at >= header.size() || header[at] != '}')) return fail("a malformed header");
  }
  if (descr.empty() || fortran < 0 || !has_shape)
    return fail("a header without descr, fortran_order or shape");
  out.descr = descr;
  out.fortran = fortran == 1;
  return true;
}

bool parse_npy_scalar(const std::string& descr, NpyScalar& type) {
  if (descr.size() != 3) return false;
  const char order = descr[0], kind = descr[1];
  const std::size_t bytes = descr[2] >= '1' && descr[2] <= '8' ? std::size_t(descr[2] - '0') : 0;
  // '|' (no order) only for single bytes, as numpy writes them; '<' and '>' for any size.
  if (!(order == '<' || order == '>' || (order == '|' && bytes == 1))) return false;
  const bool sized =
      kind == 'f'   ? bytes == 2 || bytes == 4 || bytes == 8
      : kind == 'b' ? bytes == 1
                    : (kind == 'u' || kind == 'i') && (bytes == 1 || bytes == 2 || bytes == 4 || bytes == 8);
  if (!sized) return false;
  type.kind = kind, type.bytes = bytes, type.big_endian = order == '>';
  return true;
}

double npy_scalar_value(const unsigned char* p, const NpyScalar& type) {
  const std::size_t bytes = type.bytes;
  std::uint64_t bits = 0;  // the number's bits, whatever this machine's order
  for (std::size_t b = 0; b < bytes; ++b) bits = bits << 8 | p[type.big_endian ? b : bytes - 1 - b];
  if (type.kind == 'f' && bytes == 8) {
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  if (type.kind == 'f' && bytes == 4) {
    const std::uint32_t b32 = static_cast<std::uint32_t>(bits);
    float f;
    std::memcpy(&f, &b32, 4);
    return f;
  }
  if (type.kind == 'f') {  // IEEE half: sign, 5 exponent bits, 10 mantissa bits
    const int exponent = int(bits >> 10 & 31), mantissa = int(bits & 1023);
    const double v = exponent == 31  ? (mantissa ? std::nan("") : HUGE_VAL)
                     : exponent == 0 ? std::ldexp(mantissa, -24)
                                     : std::ldexp(1024 + mantissa, exponent - 25);
    return bits >> 15 & 1 ? -v : v;
  }
  if (type.kind == 'i') {  // two's complement of `bytes` bytes
    const unsigned shift = unsigned(64 - 8 * bytes);
    return double(static_cast<std::int64_t>(bits << shift) >> shift);
  }
  return double(type.kind == 'b' ? bits != 0 : bits);
}

namespace {

/// The first bytes of a NumPy .npy file (np.save).
constexpr char kNpyMagic[] = "\x93NUMPY";

/// Reads a NumPy .npy file's sets, after its magic: an (n, 2) or (n, 3) array of float64 or float32 (either
/// byte order), in C or Fortran order, is one set; a (sets, n, 2) or (sets, n, 3) array in C order
/// (kdm sample --sets) is that many. The header is untrusted (read_npy_header), and the data read as it comes
/// (a header that promises more than the file holds allocates nothing of it).
bool read_npy(std::istream& in, const std::string& path, std::vector<PointSet>& sets, std::string& error) {
  auto fail = [&](const std::string& what) {
    error = path + ": NumPy .npy file: " + what;
    return false;
  };
  std::streambuf* buffer = in.rdbuf();
  auto read = [&](void* to, std::size_t n) {
    return static_cast<std::size_t>(buffer->sgetn(static_cast<char*>(to), static_cast<std::streamsize>(n))) ==
           n;
  };
  NpyHeader h;
  std::string what;
  if (!read_npy_header(*buffer, h, what)) return fail(what);
  const std::string& descr = h.descr;
  const int fortran = h.fortran ? 1 : 0;
  const std::vector<std::uint64_t>& shape = h.shape;
  NpyScalar type;
  if (!parse_npy_scalar(descr, type) || type.kind != 'f' || type.bytes < 4)
    return fail("data of type '" + excerpt(descr) +
                "': expected float64 or float32 ('<f8' or '<f4', or big-endian '>f8' or '>f4')");
  const std::size_t width = type.bytes;
  std::string dims;
  for (std::size_t i = 0; i < shape.size(); ++i) dims += (i ? ", " : "") + std::to_string(shape[i]);
  const bool several = shape.size() == 3;  // (sets, n, dim)
  if ((shape.size() != 2 && !several) || (shape.back() != 2 && shape.back() != 3))
    return fail("an array of shape (" + dims + "): expected (n, 2) or (n, 3) points, or (sets, n, 2) or " +
                "(sets, n, 3)");
  if (several && fortran)
    return fail("a (sets, n, dim) array in Fortran order: save it in C order (np.ascontiguousarray)");
  const std::uint64_t n = shape[shape.size() - 2], dim = shape.back(), per_set = n * dim;
  const std::uint64_t count = several ? shape[0] * per_set : per_set;  // each axis < 2^40: no overflow
  if (count == 0) {
    error = "point file '" + path + "' holds no points";
    return false;
  }
  PointSet set;
  set.dim = static_cast<int>(dim);
  set.coords.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(per_set, 1 << 20)));
  unsigned char chunk[1 << 14];
  for (std::uint64_t done = 0; done < count;) {
    const std::size_t values =
        static_cast<std::size_t>(std::min<std::uint64_t>(count - done, sizeof chunk / width));
    if (!read(chunk, values * width))
      return fail("cut short: its header promises " + std::to_string(count) + " values");
    for (std::size_t k = 0; k < values; ++k) {
      const double v = npy_scalar_value(chunk + k * width, type);
      if (!std::isfinite(v)) {
        const std::uint64_t at = done + k;
        // Its numpy index, [row, column] or [set, row, column], as numpy users count: from 0.
        const std::uint64_t row = fortran ? at % n : at % per_set / dim, column = fortran ? at / n : at % dim;
        return fail("a non-finite coordinate at [" +
                    (several ? std::to_string(at / per_set) + ", " : std::string()) + std::to_string(row) +
                    ", " + std::to_string(column) + "]");
      }
      set.coords.push_back(v);
      if (several && set.coords.size() == per_set) {
        sets.push_back(std::move(set));
        set = PointSet{};
        set.dim = static_cast<int>(dim);
      }
    }
    done += values;
  }
  if (several) return true;
  if (fortran) {  // column after column: interleave them
    std::vector<double> rows(set.coords.size());
    for (std::uint64_t i = 0; i < n; ++i)
      for (std::uint64_t a = 0; a < dim; ++a) rows[i * dim + a] = set.coords[a * n + i];
    set.coords.swap(rows);
  }
  sets.push_back(std::move(set));
  return true;
}

}  // namespace

bool read_point_sets(std::istream& in, const std::string& path, std::vector<PointSet>& sets,
                     std::string& error) {
  sets.clear();
  if (in.rdbuf()->sgetc() == static_cast<unsigned char>(kNpyMagic[0])) {
    char magic[6];
    const std::streamsize got = in.rdbuf()->sgetn(magic, 6);
    if (got == 6 && std::memcmp(magic, kNpyMagic, 6) == 0) return read_npy(in, path, sets, error);
    error = path + ": not a NumPy .npy file: it starts with '" +
            excerpt(std::string(magic, static_cast<std::size_t>(got))) + "', not \\x93NUMPY";
    return false;
  }
  PointSet current;
  int file_dim = 0;
  std::string line;
  int line_no = 0;
  Header header;  // columns 0: no header, every field of a row a coordinate
  auto finish_set = [&] {
    if (!current.coords.empty()) sets.push_back(current);
    current.coords.clear(), current.classes.clear();
  };
  bool too_long = false;
  std::vector<double> values;
  while (read_line(in, line, too_long)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte-order mark
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      finish_set();
      continue;
    }
    // A CSV file's column header (ours, kdm query's, another tool's): the columns named x, y, z and class.
    if (line_no == 1 && is_header(line.substr(first))) {
      std::string problem;
      if (!parse_header(line.substr(first), header, problem)) {
        error = path + ":1: " + problem;
        return false;
      }
      continue;
    }
    values.clear();
    const std::string where = path + ":" + std::to_string(line_no);
    if (header.columns) {  // the named columns; the others may hold anything
      const std::vector<std::string> fields = split_fields(line.substr(first));
      if (static_cast<int>(fields.size()) != header.columns) {
        error = where + ": expected " + std::to_string(header.columns) + " columns, found " +
                std::to_string(fields.size());
        return false;
      }
      for (int column : {header.x, header.y, header.z, header.label}) {
        if (column < 0) continue;
        double v;
        if (!parse_number(fields[column], v)) {
          error = where + (column == header.label ? ": a class must be an integer 0 to 255, not '" +
                                                        excerpt(fields[column]) + "'"
                                                  : ": malformed number in '" + excerpt(line) + "'");
          return false;
        }
        if (column == header.label) {
          if (!(v >= 0 && v <= 255 && v == std::floor(v))) {
            error = where + ": a class must be an integer 0 to 255";
            return false;
          }
          current.classes.push_back(static_cast<std::uint8_t>(v));
          continue;
        }
        if (!std::isfinite(v)) {
          error = where + ": non-finite coordinate";
          return false;
        }
        values.push_back(v);
      }
    } else {
      // To the line's end, not its first NUL: a NUL byte is malformed, not the end of the line.
      const char* p = line.c_str() + first;
      const char* const line_end = line.c_str() + line.size();
      while (p < line_end) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p) {
          error = where + ": malformed number in '" + excerpt(line) + "'";
          return false;
        }
        if (!std::isfinite(v)) {
          error = where + ": non-finite coordinate";
          return false;
        }
        values.push_back(v);
        p = end;
        while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') ++p;
      }
    }
    const int dim = static_cast<int>(values.size());
    if (dim != 2 && dim != 3) {
      error = where + ": expected 2 or 3 coordinates, found " + std::to_string(dim);
      return false;
    }
    if (file_dim == 0) file_dim = dim;
    if (dim != file_dim) {
      error = where + ": dimension changes from " + std::to_string(file_dim) + " to " + std::to_string(dim);
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

namespace {

/// `sets` as a NumPy .npy file (format 1.0): one set an (n, dim) little-endian float64 array in C order,
/// several (all of one size) a (sets, n, dim) one, as np.load reads them; the header padded with blanks so
/// the data start at a multiple of 64 bytes.
std::string npy_bytes(const std::vector<const PointSet*>& sets) {
  const PointSet& first = *sets.front();
  const std::string shape = (sets.size() > 1 ? std::to_string(sets.size()) + ", " : std::string()) +
                            std::to_string(first.size()) + ", " + std::to_string(first.dim);
  std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + shape + "), }";
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += static_cast<char>(dict.size() & 0xFF);
  out += static_cast<char>(dict.size() >> 8);
  out += dict;
  for (const PointSet* set : sets) {
    const std::size_t at = out.size();
    out.resize(at + set->coords.size() * sizeof(double));
    for (std::size_t i = 0; i < set->coords.size(); ++i) {  // little-endian whatever the host
      std::uint64_t bits;
      std::memcpy(&bits, &set->coords[i], sizeof bits);
      for (int b = 0; b < 8; ++b) out[at + 8 * i + b] = static_cast<char>(bits >> (8 * b) & 0xFF);
    }
  }
  return out;
}

/// Appends `set`'s points as text, one point per line, separated by `sep`.
void append_points(std::string& out, const PointSet& set, char sep) {
  char number[32];
  for (std::size_t i = 0; i < set.size(); ++i) {
    for (int k = 0; k < set.dim; ++k) {
      if (k) out += sep;
      const auto written = std::to_chars(number, number + sizeof number, set.coords[i * set.dim + k],
                                         std::chars_format::general, 17);
      out.append(number, written.ptr);
    }
    if (!set.classes.empty()) out += ',' + std::to_string(set.classes[i]);
    if (sep == ',' && set.ids.size() == set.size()) out += ',' + std::to_string(set.ids[i]);
    out += '\n';
  }
}

}  // namespace

bool write_point_set(const std::string& path, const PointSet& set, const std::vector<std::string>& header,
                     std::string& error, const std::string& format) {
  const bool csv = output_format(path, format) == ".csv";
  const bool labelled = !set.classes.empty();
  if (output_format(path, format) == ".npy") {
    if (labelled) {
      error = "'" + path + "': points with classes are written as .csv (x,y,class)";
      return false;
    }
    return write_text_file_atomic(path, npy_bytes({&set}), error);
  }
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
    out += set.dim == 3 ? "x,y,z" : labelled ? "x,y,class" : "x,y";
    out += set.ids.size() == set.size() && !set.ids.empty() ? ",id\n" : "\n";
  } else {
    for (const std::string& h : header) out += "# " + comment_safe(h) + '\n';
  }
  append_points(out, set, csv ? ',' : ' ');
  return write_text_file_atomic(path, out, error);
}

bool write_point_sets(const std::string& path, const std::vector<PointSet>& sets,
                      const std::vector<std::string>& header, const std::vector<std::string>& set_headers,
                      std::string& error, const std::string& format) {
  const std::string ext = output_format(path, format);
  if (ext != ".txt" && ext != ".npy") {
    error = "'" + path + "': several point sets are written as .txt (sets separated by '#' lines) or .npy " +
            "(a (sets, n, dim) array), not " + (ext.empty() ? std::string("a file without extension") : ext);
    return false;
  }
  if (sets.empty() || set_headers.size() != sets.size()) {
    error = "'" + path + "': no point sets, or not one header line per set";
    return false;
  }
  for (const PointSet& set : sets)
    if (!set.classes.empty() || set.size() != sets.front().size() || set.dim != sets.front().dim ||
        set.size() == 0) {
      error = "'" + path + "': point sets written together must be unlabelled, not empty, of one size and " +
              "dimension";
      return false;
    }
  if (ext == ".npy") {
    std::vector<const PointSet*> all;
    for (const PointSet& set : sets) all.push_back(&set);
    return write_text_file_atomic(path, npy_bytes(all), error);
  }
  std::string out;
  out.reserve(64 + (header.size() + sets.size()) * 80 + sets.size() * sets.front().coords.size() * 25);
  for (const std::string& h : header) out += "# " + comment_safe(h) + '\n';
  for (std::size_t k = 0; k < sets.size(); ++k) {
    out += "# " + comment_safe(set_headers[k]) + '\n';
    append_points(out, sets[k], ' ');
  }
  return write_text_file_atomic(path, out, error);
}

std::string shortest(double v) {
  char text[32];
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, v);
  return std::string(text, end.ptr);
}

std::string domain_header(bool torus, int dim, const double* extent, double aspect) {
  const std::string text = torus ? "domain torus" : "domain box";
  if (dim == 3 && extent && (extent[1] != 1 || extent[2] != 1))
    return text + ", sides " + shortest(extent[0]) + ":" + shortest(extent[1]) + ":" + shortest(extent[2]);
  if (aspect != 1) return text + ", aspect " + shortest(aspect);
  return text;
}

DomainHeader read_domain_header(std::istream& in) {
  DomainHeader header;
  // A word after `key` up to the next ',' or space, from any of the lines.
  auto word_after = [](const std::string& line, const std::string& key, std::string& word) {
    const std::size_t at = line.find(key);
    if (at == std::string::npos || !word.empty()) return;
    const std::size_t from = at + key.size();
    word = line.substr(from, line.find_first_of(", \r", from) - from);
  };
  std::string line;
  for (int i = 0; i < 4 && std::getline(in, line) && line.rfind('#', 0) == 0; ++i) {
    // "domain" follows a comma or opens the line's text ("# density ramp:4, domain box").
    for (const char* key : {", domain ", "# domain "}) word_after(line, key, header.domain);
    for (const char* key : {"aspect", "sides"})
      if (header.shape_key.empty()) {
        word_after(line, std::string(", ") + key + " ", header.shape_text);
        if (!header.shape_text.empty()) header.shape_key = key;
      }
  }
  if (header.domain != "box" && header.domain != "torus") header.domain.clear();
  return header;
}

}  // namespace kdm::tools
