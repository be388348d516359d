// SPDX-License-Identifier: GPL-3.0-or-later
// Reading golden files, with xz decompression for the large ones.
#include "golden.hpp"

#include <fstream>
#include <iterator>
#include <lzma.h>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace opencnc::conformance {

namespace {

std::string decompress_xz(const std::string& packed, const std::filesystem::path& path) {
  lzma_stream stream = LZMA_STREAM_INIT;
  if (lzma_stream_decoder(&stream, UINT64_MAX, 0) != LZMA_OK) {
    throw std::runtime_error("cannot start the xz decoder for " + path.string());
  }
  std::string out;
  std::string chunk(1 << 16, '\0');
  stream.next_in = reinterpret_cast<const std::uint8_t*>(packed.data());
  stream.avail_in = packed.size();
  lzma_ret ret = LZMA_OK;
  while (ret == LZMA_OK) {
    stream.next_out = reinterpret_cast<std::uint8_t*>(chunk.data());
    stream.avail_out = chunk.size();
    ret = lzma_code(&stream, LZMA_FINISH);
    out.append(chunk.data(), chunk.size() - stream.avail_out);
  }
  lzma_end(&stream);
  if (ret != LZMA_STREAM_END) throw std::runtime_error("corrupt xz data in " + path.string());
  return out;
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (path.extension() == ".xz") return decompress_xz(text, path);
  return text;
}

Golden parse_golden(const std::string& text) {
  Golden g;
  std::size_t pos = 0;
  bool have_exit = false;
  while (pos < text.size()) {
    const std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) break;
    const std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    if (line == "# ---") {
      if (!have_exit) throw std::runtime_error("golden file without an exit line");
      g.listing = text.substr(pos);
      return g;
    }
    if (starts_with(line, "# exit: ")) {
      g.exit_status = std::stoi(std::string(line.substr(8)));
      have_exit = true;
    } else if (starts_with(line, "# stderr: ")) {
      g.stderr_lines.emplace_back(line.substr(10));
    } else if (!starts_with(line, "# ")) {
      throw std::runtime_error("unexpected line in a golden header: " + std::string(line));
    }
  }
  throw std::runtime_error("golden file without its '# ---' line");
}

Golden load_golden(const std::filesystem::path& path) {
  try {
    return parse_golden(read_file(path));
  } catch (const std::exception& e) {  // also std::stoi's invalid_argument on a bad exit line
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

}  // namespace opencnc::conformance
