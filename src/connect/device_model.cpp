// SPDX-License-Identifier: GPL-3.0-or-later
// The MTConnect device model: components and data items in document order.
#include "opencnc/connect/device_model.hpp"

#include <cctype>
#include <stdexcept>

namespace opencnc::connect {

const char* to_string(Category c) noexcept {
  switch (c) {
    case Category::Sample:
      return "SAMPLE";
    case Category::Event:
      return "EVENT";
    case Category::Condition:
      return "CONDITION";
  }
  return "EVENT";
}

DeviceModel::DeviceModel(std::string name, std::string uuid, std::string description)
    : name_(std::move(name)), uuid_(std::move(uuid)), description_(std::move(description)) {
  components_.push_back(Component{"Device", xml_id(name_), name_, -1});
}

int DeviceModel::add_component(int parent, std::string element, std::string id, std::string name) {
  if (parent < 0 || parent >= static_cast<int>(components_.size()))
    throw std::invalid_argument("connect: a component's parent does not exist");
  for (const auto& c : components_)
    if (c.id == id) throw std::invalid_argument("connect: two components with the id " + id);
  components_.push_back(Component{std::move(element), std::move(id), std::move(name), parent});
  return static_cast<int>(components_.size()) - 1;
}

std::size_t DeviceModel::add_item(DataItem item) {
  if (item.component < 0 || item.component >= static_cast<int>(components_.size()))
    throw std::invalid_argument("connect: a data item's component does not exist");
  if (find(item.id)) throw std::invalid_argument("connect: two data items with the id " + item.id);
  for (const auto& c : components_)
    if (c.id == item.id) throw std::invalid_argument("connect: a data item has a component's id " + item.id);
  items_.push_back(std::move(item));
  return items_.size() - 1;
}

std::optional<std::size_t> DeviceModel::find(std::string_view id) const noexcept {
  for (std::size_t i = 0; i < items_.size(); ++i)
    if (items_[i].id == id) return i;
  return std::nullopt;
}

int DeviceModel::find_component(std::string_view element) const noexcept {
  for (std::size_t i = 0; i < components_.size(); ++i)
    if (components_[i].element == element) return static_cast<int>(i);
  return -1;
}

std::string xml_id(std::string_view text) {
  std::string id;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    id += std::isalnum(u) || c == '_' || c == '-' ? c : '_';
  }
  // Not id.insert(0, "_"): GCC 12 warns of an overlapping copy inside it (-Wrestrict, a false alarm).
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id.front())) || id.front() == '-') id = "_" + id;
  return id;
}

}  // namespace opencnc::connect
