// Inputs that the fuzzers of tests/fuzz found to crash a parser or let an exception other than
// finecap::Error escape, each kept as a string: every one must now be refused with an Error
// naming the file.
#include <string>

#include <gtest/gtest.h>

#include "finecap/camera_io.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// OpenCV's YAML parser threw std::length_error on this intri.yml.
TEST(FuzzRegression, IntriYmlThatMadeOpenCvThrowALengthError) {
  const std::string dir = MakeTempDir("fuzz_intri");
  WriteText(dir + "/intri.yml", std::string("%YAML:1.\n   t:d\n   :\x01", 21));
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "malformed OpenCV YAML/XML file"});
}

}  // namespace
}  // namespace finecap
