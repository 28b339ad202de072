// A file replaced so that a power cut leaves either the old or the new version, never a mix: written to
// PATH.tmp, fsync'd, renamed over PATH, and the folder fsync'd. Non-RT.
#pragma once

#include <string>

namespace loom::firmware {

// Throws std::runtime_error naming the path and the errno text on any failure (the old file stays).
void write_file_durably(const std::string& path, const std::string& body);

}  // namespace loom::firmware
