#include "colonflat/core/library_output.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace cf {

LibraryOutputCapture::LibraryOutputCapture() {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  char name[] = "/tmp/colonflat-lib-output-XXXXXX";
  file_ = ::mkstemp(name);
  if (file_ < 0) return;
  ::unlink(name);
  saved_out_ = ::dup(1);
  saved_err_ = ::dup(2);
  ::dup2(file_, 1);
  ::dup2(file_, 2);
}

void LibraryOutputCapture::restore() {
  if (saved_err_ < 0) return;
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  ::dup2(saved_out_, 1);
  ::dup2(saved_err_, 2);
  ::close(saved_out_);
  ::close(saved_err_);
  saved_out_ = saved_err_ = -1;
}

LibraryOutputCapture::~LibraryOutputCapture() {
  restore();
  if (file_ >= 0) ::close(file_);
}

std::string LibraryOutputCapture::text() {
  restore();
  if (file_ < 0) return "";
  std::string raw;
  char buf[4096];
  ::lseek(file_, 0, SEEK_SET);
  for (ssize_t n; (n = ::read(file_, buf, sizeof buf)) > 0 && raw.size() < (1u << 16);) raw.append(buf, std::size_t(n));
  std::string out;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '\033') {  // ANSI escape: skip to its final letter
      while (i < raw.size() && !std::isalpha(static_cast<unsigned char>(raw[i]))) ++i;
      continue;
    }
    if (raw[i] == '\n' || raw[i] == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
      continue;
    }
    out += raw[i];
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  return out;
}

}  // namespace cf
