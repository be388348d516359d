// SPDX-License-Identifier: GPL-3.0-or-later
// `path=` filters: libxml2's XPath over the device model as a namespace-free probe tree.
#include "path_filter.hpp"

#include <libxml/tree.h>
#include <libxml/xpath.h>

#include <memory>

namespace opencnc::connect {

namespace {

const xmlChar* x(const char* s) {
  return reinterpret_cast<const xmlChar*>(s);
}
const xmlChar* x(const std::string& s) {
  return x(s.c_str());
}

struct DocFree {
  void operator()(xmlDocPtr d) const { xmlFreeDoc(d); }
};
struct ContextFree {
  void operator()(xmlXPathContextPtr c) const { xmlXPathFreeContext(c); }
};
struct ObjectFree {
  void operator()(xmlXPathObjectPtr o) const { xmlXPathFreeObject(o); }
};

/// The probe's element tree (Devices/Device/Components/…/DataItems/DataItem), built with the
/// attributes an XPath may test: id, name, type, subType, category, units.
std::unique_ptr<xmlDoc, DocFree> probe_tree(const DeviceModel& model) {
  std::unique_ptr<xmlDoc, DocFree> doc(xmlNewDoc(x("1.0")));
  xmlNodePtr root = xmlNewNode(nullptr, x("MTConnectDevices"));
  xmlDocSetRootElement(doc.get(), root);
  xmlNodePtr devices = xmlNewChild(root, nullptr, x("Devices"), nullptr);
  const auto& comps = model.components();
  std::vector<xmlNodePtr> node(comps.size(), nullptr), child_list(comps.size(), nullptr),
      item_list(comps.size(), nullptr);
  for (std::size_t i = 0; i < comps.size(); ++i) {
    xmlNodePtr parent = devices;
    if (comps[i].parent >= 0) {
      const auto p = static_cast<std::size_t>(comps[i].parent);
      if (child_list[p] == nullptr) child_list[p] = xmlNewChild(node[p], nullptr, x("Components"), nullptr);
      parent = child_list[p];
    }
    node[i] = xmlNewChild(parent, nullptr, x(comps[i].element), nullptr);
    xmlNewProp(node[i], x("id"), x(comps[i].id));
    if (!comps[i].name.empty()) xmlNewProp(node[i], x("name"), x(comps[i].name));
  }
  for (const auto& item : model.items()) {
    const auto c = static_cast<std::size_t>(item.component);
    if (item_list[c] == nullptr) item_list[c] = xmlNewChild(node[c], nullptr, x("DataItems"), nullptr);
    xmlNodePtr n = xmlNewChild(item_list[c], nullptr, x("DataItem"), nullptr);
    xmlNewProp(n, x("id"), x(item.id));
    xmlNewProp(n, x("category"), x(to_string(item.category)));
    xmlNewProp(n, x("type"), x(item.type));
    if (!item.sub_type.empty()) xmlNewProp(n, x("subType"), x(item.sub_type));
    if (!item.units.empty()) xmlNewProp(n, x("units"), x(item.units));
  }
  return doc;
}

void mark(const DeviceModel& model, xmlNodePtr n, std::vector<bool>& selected) {
  if (n == nullptr || n->type != XML_ELEMENT_NODE) return;
  if (xmlStrEqual(n->name, x("DataItem"))) {
    xmlChar* id = xmlGetProp(n, x("id"));
    if (id != nullptr) {
      if (auto i = model.find(reinterpret_cast<const char*>(id))) selected[*i] = true;
      xmlFree(id);
    }
    return;
  }
  for (xmlNodePtr c = n->children; c != nullptr; c = c->next) mark(model, c, selected);
}

void quiet(void*, xmlErrorPtr) {}

}  // namespace

std::optional<std::vector<bool>> select_items(const DeviceModel& model, std::string_view xpath,
                                              std::string* error) {
  auto doc = probe_tree(model);
  std::unique_ptr<xmlXPathContext, ContextFree> ctx(xmlXPathNewContext(doc.get()));
  // libxml2 reports a malformed expression on stderr by default: the caller reports it instead.
  xmlSetStructuredErrorFunc(nullptr, quiet);
  std::unique_ptr<xmlXPathObject, ObjectFree> result(
      xmlXPathEvalExpression(x(std::string(xpath)), ctx.get()));
  xmlSetStructuredErrorFunc(nullptr, nullptr);
  if (!result) {
    if (error) *error = "the path is not a valid XPath expression: " + std::string(xpath);
    return std::nullopt;
  }
  std::vector<bool> selected(model.items().size(), false);
  bool any = false;
  if (result->type == XPATH_NODESET && result->nodesetval != nullptr) {
    for (int i = 0; i < result->nodesetval->nodeNr; ++i)
      mark(model, result->nodesetval->nodeTab[i], selected);
    for (bool b : selected) any = any || b;
  }
  if (!any) {
    if (error) *error = "the path selects no data item: " + std::string(xpath);
    return std::nullopt;
  }
  return selected;
}

}  // namespace opencnc::connect
