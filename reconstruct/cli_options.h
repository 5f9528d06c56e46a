// Command-line options shared by gdpt-reconstruct and gdpt-merge: one message format for bad
// arguments (exit status 2) and one parser per shared option.
#pragma once

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "reconstruct/reconstruct.h"

namespace gdpt::cli {

struct Parser {
  const char* program;  // prefix of every message

  [[noreturn]] void bad_arguments(const std::string& message) const {
    std::fprintf(stderr, "%s: %s (see --help)\n", program, message.c_str());
    std::exit(2);
  }

  double number(const std::string& option, const std::string& text) const {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0')
      bad_arguments(option + " expects a number, got '" + text + "'");
    return v;
  }

  float alpha(const std::string& option, const std::string& text) const {
    const double a = number(option, text);
    if (!(a > 0) || a > 1e30) bad_arguments("--alpha must be > 0");
    return float(a);
  }

  int threads(const std::string& option, const std::string& text) const {
    const double t = number(option, text);
    if (t < 0 || t > 4096 || t != int(t)) bad_arguments("--threads must be an integer >= 0");
    return int(t);
  }

  ReconstructionNorm norm(const std::string& text) const {
    std::string n = text;
    for (char& c : n) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (n == "l1") return ReconstructionNorm::L1;
    if (n == "l2") return ReconstructionNorm::L2;
    if (n == "weighted") return ReconstructionNorm::Weighted;
    if (n == "feature") return ReconstructionNorm::Feature;
    if (n == "none") return ReconstructionNorm::None;
    bad_arguments("--norm must be l1, l2, weighted, feature or none, got '" + text + "'");
  }
};

}  // namespace gdpt::cli
