// An output file written under a temporary name and renamed into place when
// complete, so that no reader (nor the next tool of a pipeline) takes half a
// file for a whole one: a full disk, an error or a crash leaves either the
// finished file or one whose name says it is not.
//
//   OutputFile out("run/stats.json");          // writes go to run/stats.json.partial
//   write_everything(out.writing_path());
//   out.commit();                               // renames it to run/stats.json
//
// Destroyed without commit() (an exception on the way), the temporary file
// is removed, or with OnFailure::KeepPartial kept under its `.partial` name
// (what was written may still be useful: trajectories up to the failure)
// with a warning on stderr that names it.
#pragma once

#include <string>

namespace throng {

class OutputFile {
 public:
  enum class OnFailure { Remove, KeepPartial };
  static constexpr const char* kPartialSuffix = ".partial";

  explicit OutputFile(std::string path, OnFailure on_failure = OnFailure::Remove);
  ~OutputFile();
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  const std::string& path() const { return path_; }                  // the final name
  const std::string& writing_path() const { return writing_path_; }  // path + ".partial"
  bool committed() const { return committed_; }
  // Renames the finished file into place (replacing an older one). Throws
  // Error naming the file when the rename fails. Idempotent.
  void commit();

 private:
  void abandon() noexcept;
  std::string path_, writing_path_;
  OnFailure on_failure_ = OnFailure::Remove;
  bool committed_ = false;
};

}  // namespace throng
