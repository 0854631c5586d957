#pragma once
// Error types and the exit codes they map to. Every `colonflat` command turns an exception into
// exactly one line on stderr and one of these exit codes; nothing logs an error and returns 0.
//
//   0  success
//   1  processing failed (a postcondition did not hold, an algorithm could not finish)
//   2  usage error (unknown option, missing argument, parameter out of range)
//   3  bad input (missing / unreadable / truncated / invalid file, mesh or volume with defects)
#include <stdexcept>
#include <string>

namespace cf {

enum ExitCode : int { kExitOk = 0, kExitFailure = 1, kExitUsage = 2, kExitBadInput = 3 };

// Base error: a message meant for the user, without the "error:" prefix.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, int exit_code = kExitFailure)
      : std::runtime_error(what), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

// A command-line or parameter problem ("--target-genus must be >= 0 (got -1)").
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& what) : Error(what, kExitUsage) {}
};

// A problem with an input file; the message starts with the file name.
class InputError : public Error {
 public:
  InputError(const std::string& file, const std::string& problem)
      : Error(file + ": " + problem, kExitBadInput), file_(file), problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_, problem_;
};

// A precondition of an algorithm on in-memory data ("input must be genus 0; got genus 3").
class PreconditionError : public Error {
 public:
  explicit PreconditionError(const std::string& what) : Error(what, kExitBadInput) {}
};

}  // namespace cf
