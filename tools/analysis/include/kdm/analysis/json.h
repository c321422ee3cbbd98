// A minimal streaming JSON writer (objects, arrays, strings, numbers, booleans; non-finite numbers become
// null) and the metrics.json document of an AnalysisReport.
#pragma once

#include <string>
#include <vector>

#include "kdm/analysis/report.h"

namespace kdm::analysis {

/// Builds a JSON text; the caller is responsible for balanced begin/end calls. Not thread-safe (one
/// writer per thread). Numbers are written with 10 significant digits.
class JsonWriter {
 public:
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(const std::string& k);  ///< inside an object, before each value
  JsonWriter& value(double v);
  JsonWriter& value(long long v);
  JsonWriter& value(std::size_t v) { return value(static_cast<long long>(v)); }
  JsonWriter& value(int v) { return value(static_cast<long long>(v)); }
  JsonWriter& value(bool v);
  JsonWriter& value(const std::string& v);
  JsonWriter& value(const char* v) { return value(std::string(v)); }
  JsonWriter& value(const std::vector<double>& v);  ///< an array of numbers
  const std::string& str() const { return out_; }

 private:
  void separator();
  std::string out_;
  std::vector<bool> first_;  // per open container: no element written yet
  bool after_key_ = false;
};

/// Escapes `s` as a JSON string literal including the quotes. Thread-safe.
std::string json_quote(const std::string& s);

/// The metrics document: inputs, NN statistics, spectrum statistics with the RAPS curve, g(r), density and
/// tiling results (only the parts that were computed). Thread-safe.
std::string metrics_json(const AnalysisReport& report, const std::vector<std::string>& inputs);

}  // namespace kdm::analysis
