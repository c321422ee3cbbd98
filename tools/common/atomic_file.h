// Writing output files whole or not at all, for the command line and the Python package.
#pragma once

#include <string>

namespace kdm::tools {

/// Writes `text` (any bytes) to `path` atomically (temporary file, then rename), every write checked; "-"
/// is standard output.
bool write_text_file_atomic(const std::string& path, const std::string& text, std::string& error);

/// For a program that writes its files in turn from one thread (the command line): from now on SIGINT,
/// SIGTERM and SIGHUP remove the temporary file write_text_file_atomic is writing, if any, before they end
/// the process as they would have; a signal the process ignores stays ignored. A library's host (Python)
/// keeps its own handlers: it does not call this.
void remove_temporary_files_on_signals();

namespace detail {
/// The temporary file being written, as write_text_file_atomic marks it (null: none); for tests.
void mark_temporary_file(const char* path);
}  // namespace detail

}  // namespace kdm::tools
