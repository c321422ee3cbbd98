// Point-set text files as UTK and psa read and write them: '#' lines are comments, and a '#' line that
// follows points separates one set from the next; every other line holds D coordinates in [0, 1)
// (separated by blanks or commas). A first line of column names is a CSV header: the columns named x and
// y (and z; and class or label for labelled points, several classes), trimmed and in any case, in any
// order, are read and the others skipped (kdm query's "x,y,tile_x,tile_y,rank,level[,class],depth" too).
// A NumPy .npy file (np.save of an (n, 2) or (n, 3) float64 or float32 array) is read as one set, one of
// shape (sets, n, 2) or (sets, n, 3) (C order) as that many sets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

namespace kdm::tools {

/// One point set: `dim` coordinates per point, interleaved (x0 y0 x1 y1 ...), and for labelled 2D points
/// (several classes) each point's class.
struct PointSet {
  int dim = 2;
  std::vector<double> coords;
  std::vector<std::uint8_t> classes;  ///< empty, or one class (0 … 255) per point
  /// Empty, or each point's dot radius as a fraction (0 … 1) of the picture's (pictures only).
  std::vector<float> sizes;
  /// Empty, or a number per point that names it wherever it shows (kdm stipple's tiles: the runtime's
  /// point key, the same in every frame): a .csv's id column.
  std::vector<std::uint64_t> ids;
  std::size_t size() const { return dim > 0 ? coords.size() / dim : 0; }
};

/// Whether `path` ends in `extension` (".csv"), in any case: ".CSV" is a CSV file too.
bool has_extension(const std::string& path, const char* extension);

/// The output path that stands for standard output (`-o -`): its format is named apart (`--format`).
inline constexpr const char* kStandardOutput = "-";

/// The format `path` is written in, as a lower-case extension (".csv"): `format` when given ("csv" or
/// ".csv"), else the path's own extension; "" when neither names one.
std::string output_format(const std::string& path, const std::string& format = "");

/// `extensions` as a choice in a message: ".png, .svg, .txt or .csv".
std::string extension_list(const std::vector<const char*>& extensions);

/// Checks, before any long work, that `path` can be written as one of `extensions` (a list such as
/// {".csv", ".png"}): its format (output_format(path, format)) is one of them, it is not a directory,
/// and its directory exists. kStandardOutput needs `format`. Returns false with `error` naming the path
/// and what is wrong.
bool check_output_path(const std::string& path, const std::vector<const char*>& extensions,
                       std::string& error, const std::string& format = "");

/// `line` made safe as one comment line of a text or SVG file: line breaks become spaces, and "--" (which
/// would end an XML comment) becomes "- -".
std::string comment_safe(std::string line);

/// The shortest text that reads back as `v` (std::to_chars): "0.8", not %.17g's 0.80000000000000004.
std::string shortest(double v);

/// The header's words for the domain a point file's points lie in, which kdm analyze reads back
/// (read_domain_header): "domain box" or "domain torus" (`torus`: it wraps around), then ", sides X:Y:Z"
/// for a 3D box of its own sides `extent` (`dim` 3), else ", aspect A" for a width over height `aspect`
/// other than 1. `extent` may be null for 2D.
std::string domain_header(bool torus, int dim, const double* extent, double aspect);

/// What a point file's first header lines ('#' lines, at most 4) say of its domain; each field "" when
/// unsaid.
struct DomainHeader {
  std::string domain;      ///< "box" or "torus"
  std::string shape_key;   ///< "aspect" or "sides"
  std::string shape_text;  ///< "2" or "2:1:0.5", as written
};

/// Reads the header lines at the start of `in` (a point file, or the first bytes of one).
DomainHeader read_domain_header(std::istream& in);

/// Reads every set in `path` ("-": standard input), text or .npy (known by its first bytes). All sets must
/// share one dimension (2 or 3); coordinates must be finite.
/// Returns false with `error` naming the file, line and problem (empty file, malformed or non-finite value).
bool read_point_sets(const std::string& path, std::vector<PointSet>& sets, std::string& error);

/// The same for a stream holding a point file's text; `name` stands for the file in error messages.
bool read_point_sets(std::istream& in, const std::string& name, std::vector<PointSet>& sets,
                     std::string& error);

/// A NumPy .npy file's header (np.save): its element type ('<f8', '|u1', ...), order and shape.
struct NpyHeader {
  std::string descr;
  bool fortran = false;              ///< column-major data (np.asfortranarray, a transposed array)
  std::vector<std::uint64_t> shape;  ///< at most 8 axes, each under 2^40
};

/// Reads a .npy header from `in`, whose six-byte magic ("\x93NUMPY") has been read: the version, the length
/// and the dict np.save writes. The header is untrusted: parsed as the few literals np.save writes, sizes
/// bounded. Returns false with `what` naming the problem ("cut short in its header", "a malformed 'shape'").
bool read_npy_header(std::streambuf& in, NpyHeader& header, std::string& what);

/// A .npy element type kdm reads (NpyHeader::descr): a real number in either byte order, as np.save writes
/// it ('<f8', '>f4', '|u1', '|b1').
struct NpyScalar {
  char kind = 0;          ///< 'f' float, 'i' signed integer, 'u' unsigned integer, 'b' bool
  std::size_t bytes = 0;  ///< float 2, 4 or 8; integer 1, 2, 4 or 8; bool 1
  bool big_endian = false;
};

/// Parses `descr` into `type`; false for anything else (complex numbers, strings, records, datetimes).
bool parse_npy_scalar(const std::string& descr, NpyScalar& type);

/// The value of the element of `type` at `bytes` (as stored in the file), whatever this machine's order.
double npy_scalar_value(const unsigned char* bytes, const NpyScalar& type);

/// Writes `set` as text ('#' header lines from `header`, one point per line, 17 significant digits),
/// or as CSV when its format (output_format(path, format)) is ".csv" (with a class column for labelled
/// points, which only CSV carries: false with `error` for a labelled set and another format). Atomic
/// (temporary file, then rename); kStandardOutput writes to standard output.
bool write_point_set(const std::string& path, const PointSet& set, const std::vector<std::string>& header,
                     std::string& error, const std::string& format = "");

/// Writes several unlabelled sets of one size and dimension (kdm sample --sets): as text, the `header`
/// lines, then for each set a '#' line from set_headers[k] (one per set) and its points, so that
/// read_point_sets() reads them back as separate sets; as .npy (output_format(path, format)), a (sets, n,
/// dim) float64 array (one set: (n, dim), as write_point_set). Other formats, labelled or unequal sets:
/// false with `error` naming the problem. Atomic; kStandardOutput writes to standard output.
bool write_point_sets(const std::string& path, const std::vector<PointSet>& sets,
                      const std::vector<std::string>& header, const std::vector<std::string>& set_headers,
                      std::string& error, const std::string& format = "");

}  // namespace kdm::tools
