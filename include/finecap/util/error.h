// The one error type that finecap raises for bad input: a missing or malformed file, a value out
// of range, a capture whose parts disagree. Its message always names the file (or the config key)
// and the problem, so that the command line can print it as it is and exit non-zero.
#ifndef FINECAP_UTIL_ERROR_H_
#define FINECAP_UTIL_ERROR_H_

#include <stdexcept>
#include <string>

namespace finecap {

class Error : public std::runtime_error {
 public:
  // `where` is the file, folder or config key the problem is in; it may be empty.
  Error(const std::string& where, const std::string& problem)
      : std::runtime_error(where.empty() ? problem : where + ": " + problem),
        where_(where),
        problem_(problem) {}

  // The two parts of the message, e.g. for a caller that names `where` otherwise (the config
  // layer reports an options struct's field, "RefineOptions::sigma_hat", as its config key).
  const std::string& where() const { return where_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string where_;
  std::string problem_;
};

// Throws Error(where, problem) unless `condition` holds.
inline void Require(bool condition, const std::string& where, const std::string& problem) {
  if (!condition) throw Error(where, problem);
}

}  // namespace finecap

#endif  // FINECAP_UTIL_ERROR_H_
