#include "core/output_file.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <system_error>
#include <utility>

#include "core/error.h"

namespace throng {

OutputFile::OutputFile(std::string path, OnFailure on_failure)
    : path_(std::move(path)), writing_path_(path_ + kPartialSuffix), on_failure_(on_failure) {}

OutputFile::~OutputFile() { abandon(); }

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)),
      writing_path_(std::move(other.writing_path_)),
      on_failure_(other.on_failure_),
      committed_(other.committed_) {
  other.committed_ = true;  // the moved-from object owns no file
}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    abandon();
    path_ = std::move(other.path_);
    writing_path_ = std::move(other.writing_path_);
    on_failure_ = other.on_failure_;
    committed_ = other.committed_;
    other.committed_ = true;
  }
  return *this;
}

void OutputFile::commit() {
  if (committed_) return;
  std::error_code ec;
  std::filesystem::rename(writing_path_, path_, ec);
  if (ec) throw Error("cannot rename the finished file into place: " + ec.message(), Location{path_, 0, 0, {}});
  committed_ = true;
}

void OutputFile::abandon() noexcept {
  if (committed_) return;
  committed_ = true;
  std::error_code ec;
  if (!std::filesystem::exists(writing_path_, ec)) return;
  try {
    if (on_failure_ == OnFailure::KeepPartial) {
      spdlog::warn("{} is incomplete: kept as {}", path_, writing_path_);
    } else {
      std::filesystem::remove(writing_path_, ec);
    }
  } catch (...) {
    // Logging failed: nothing more to do while unwinding.
  }
}

}  // namespace throng
