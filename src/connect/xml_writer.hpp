// SPDX-License-Identifier: GPL-3.0-or-later
// connect::XmlWriter — libxml2's text writer into memory, with errors as exceptions: the documents
// are escaped and well-formed by construction.
#pragma once

#include <libxml/xmlwriter.h>

#include <string>
#include <string_view>

namespace opencnc::connect {

class XmlWriter {
 public:
  XmlWriter();
  ~XmlWriter();
  XmlWriter(const XmlWriter&) = delete;
  XmlWriter& operator=(const XmlWriter&) = delete;

  void start(std::string_view element);
  void attribute(std::string_view name, std::string_view value);
  void text(std::string_view text);
  void end();
  /// Closes every open element and returns the document.
  std::string finish();

 private:
  xmlBufferPtr buffer_ = nullptr;
  xmlTextWriterPtr writer_ = nullptr;
};

}  // namespace opencnc::connect
