// One error type for every parser and loader: a message plus where it happened.
#pragma once

#include <stdexcept>
#include <string>

namespace throng {

// Where an error happened: a file position ("scene.yaml:12:5") and/or a field
// path ("groups[2].speed"). Empty members are left out when printed.
struct Location {
  std::string file;
  int line = 0;    // 1-based; 0 = unknown
  int column = 0;  // 1-based; 0 = unknown
  std::string field;

  std::string to_string() const;
  bool empty() const { return file.empty() && line == 0 && field.empty(); }
};

class Error : public std::runtime_error {
 public:
  explicit Error(std::string message, Location where = {});
  const std::string& message() const { return message_; }
  const Location& location() const { return where_; }

 private:
  std::string message_;
  Location where_;
};

// Helpers for the common cases.
Location at_line(std::string file, int line, int column = 0);
Location at_field(std::string field, std::string file = {});

}  // namespace throng
