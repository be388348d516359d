// SPDX-License-Identifier: GPL-3.0-or-later
// Comments: plain comments, (MSG,) (DEBUG,) (PRINT,) (LOG*,) (ABORT,) with parameter
// values substituted where LinuxCNC substitutes them.
#include <cctype>
#include <cmath>
#include <cstdio>

#include "comments.hpp"
#include "gcode_error.hpp"
#include "opencnc/gcode/state.hpp"
#include "output.hpp"
#include "params.hpp"

namespace opencnc::gcode {

namespace {

bool starts_with_nocase(std::string_view text, std::string_view prefix) noexcept {
  if (text.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(text[i])) != prefix[i]) return false;
  }
  return true;
}

void append_value(std::string& out, bool found, double value) {
  if (!found) {
    out += "######";
    return;
  }
  if (std::fabs(value) < 1e-4) value = 0.0;   // no "-0.000000" for values that print as zero
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%f", value);
  if (n < 0 || n >= 30) out += "######";
  else out.append(buf, static_cast<std::size_t>(n));
}

// The comment's text with #n and #<name> replaced by their values ("######" for none).
std::string expand_parameters(std::string_view text, const InterpState& st, ParameterHost& params) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c != '#') {
      out += c;
      ++i;
      continue;
    }
    ++i;
    if (i >= text.size()) {
      out += "######";
      break;
    }
    if (std::isdigit(static_cast<unsigned char>(text[i]))) {
      long n = 0;
      while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
        if (n < 1000000) n = n * 10 + (text[i] - '0');
        ++i;
      }
      const bool found = n >= 0 && n < kParameterCount;
      append_value(out, found, found ? st.parameters[static_cast<std::size_t>(n)] : 0.0);
    } else if (text[i] == '<') {
      ++i;
      std::string name;
      while (i < text.size() && text[i] != '>' && text[i] != ')') {
        if (!std::isspace(static_cast<unsigned char>(text[i]))) name += static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
        ++i;
      }
      // A name never closed ends the text there (LinuxCNC prints what came before it).
      if (i >= text.size() || text[i] != '>') break;
      ++i;
      double v = 0;
      const bool found = params.named_value(name, v);
      append_value(out, found, v);
    } else {
      out += '#';
    }
  }
  return out;
}

}  // namespace

void convert_comment(std::string_view comment, const InterpState& st, ParameterHost& params, Output& out) {
  auto expand = [&](std::string_view text) { return expand_parameters(text, st, params); };
  std::size_t start = 0;
  while (start < comment.size() && std::isspace(static_cast<unsigned char>(comment[start]))) ++start;
  const std::string_view c = comment.substr(start);
  if (starts_with_nocase(c, "msg,")) {
    out.message(c.substr(4));
  } else if (starts_with_nocase(c, "debug,")) {
    const std::string text = expand(c.substr(6));
    if (st.parameters[5599] > 0.0) out.message(text);
  } else if (starts_with_nocase(c, "print,")) {
    out.print(expand(c.substr(6)));
  } else if (starts_with_nocase(c, "log,")) {
    out.log(expand(c.substr(4)));
  } else if (starts_with_nocase(c, "logopen,")) {
    out.log_open(c.substr(8));
  } else if (starts_with_nocase(c, "logappend,")) {
    out.log_append(c.substr(10));
  } else if (starts_with_nocase(c, "abort,")) {
    fail(ErrorCode::Abort, "{}", expand(c.substr(6)));
  } else if (starts_with_nocase(c, "py,") || starts_with_nocase(c, "pyrun,") || starts_with_nocase(c, "pyreload")) {
    fail(ErrorCode::Unsupported, "embedded Python comments are not supported");
  } else if (c.size() == 8 && starts_with_nocase(c, "logclose")) {
    out.log_close();
  } else {
    out.comment(c);
  }
}

}  // namespace opencnc::gcode
