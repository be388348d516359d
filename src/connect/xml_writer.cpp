// SPDX-License-Identifier: GPL-3.0-or-later
// libxml2's text writer, wrapped.
#include "xml_writer.hpp"

#include <stdexcept>

namespace opencnc::connect {

namespace {

const xmlChar* x(const std::string& s) {
  return reinterpret_cast<const xmlChar*>(s.c_str());
}

void check(int rc, const char* what) {
  if (rc < 0) throw std::runtime_error(std::string("connect: libxml2 could not write ") + what);
}

}  // namespace

XmlWriter::XmlWriter() {
  buffer_ = xmlBufferCreate();
  if (buffer_ == nullptr) throw std::bad_alloc();
  writer_ = xmlNewTextWriterMemory(buffer_, 0);
  if (writer_ == nullptr) {
    xmlBufferFree(buffer_);
    throw std::bad_alloc();
  }
  check(xmlTextWriterSetIndent(writer_, 1), "the indent");
  check(xmlTextWriterSetIndentString(writer_, reinterpret_cast<const xmlChar*>("  ")), "the indent");
  check(xmlTextWriterStartDocument(writer_, "1.0", "UTF-8", nullptr), "the declaration");
}

XmlWriter::~XmlWriter() {
  xmlFreeTextWriter(writer_);
  xmlBufferFree(buffer_);
}

void XmlWriter::start(std::string_view element) {
  check(xmlTextWriterStartElement(writer_, x(std::string(element))), "an element");
}

void XmlWriter::attribute(std::string_view name, std::string_view value) {
  check(xmlTextWriterWriteAttribute(writer_, x(std::string(name)), x(std::string(value))), "an attribute");
}

void XmlWriter::text(std::string_view text) {
  check(xmlTextWriterWriteString(writer_, x(std::string(text))), "a text");
}

void XmlWriter::end() {
  check(xmlTextWriterEndElement(writer_), "an element's end");
}

std::string XmlWriter::finish() {
  check(xmlTextWriterEndDocument(writer_), "the document's end");
  check(xmlTextWriterFlush(writer_), "the document");
  return std::string(reinterpret_cast<const char*>(xmlBufferContent(buffer_)),
                     static_cast<std::size_t>(xmlBufferLength(buffer_)));
}

}  // namespace opencnc::connect
