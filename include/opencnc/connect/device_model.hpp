// SPDX-License-Identifier: GPL-3.0-or-later
// connect::DeviceModel — the machine as MTConnect describes it: components (axes, controller, path,
// spindle) and their data items, built from the machine profile by the contributions that observe it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::connect {

/// MTConnect's three kinds of data item.
enum class Category : std::uint8_t { Sample, Event, Condition };

/// "SAMPLE", "EVENT", "CONDITION". Any thread.
const char* to_string(Category c) noexcept;

/// One component of the device: `element` is its MTConnect element (Axes, Linear, Rotary,
/// Controller, Path, Systems, …); the device itself is component 0 (element "Device").
struct Component {
  std::string element;
  std::string id;    ///< unique in the document (an XML ID)
  std::string name;  ///< "" = none
  int parent = -1;   ///< index of the enclosing component (−1: the device)
};

/// One data item. `element` is its observation's element name in the streams ("Position",
/// "VoltageDC": the schema's spelling, which is not always the type in PascalCase).
struct DataItem {
  std::string id;  ///< unique in the document (an XML ID)
  Category category = Category::Event;
  std::string type;      ///< "POSITION", "EXECUTION", …
  std::string sub_type;  ///< "" = none
  std::string units;     ///< "" = none ("MILLIMETER", "REVOLUTION/MINUTE", …)
  std::string element;   ///< the streams' element ("Position"); conditions use the level instead
  int component = 0;     ///< index into DeviceModel::components()
};

/// The device: its identity, components and data items in document order. Built once, then
/// read-only (any thread may read it concurrently).
class DeviceModel {
 public:
  /// `name` and `uuid` identify the device in every document; `description` is free text.
  DeviceModel(std::string name, std::string uuid, std::string description);

  /// Adds a component under `parent` (0 = the device) and returns its index. Builder only.
  int add_component(int parent, std::string element, std::string id, std::string name = {});
  /// Adds a data item and returns its index. Throws std::invalid_argument on a duplicate id.
  /// Builder only.
  std::size_t add_item(DataItem item);

  const std::string& name() const noexcept { return name_; }
  const std::string& uuid() const noexcept { return uuid_; }
  const std::string& description() const noexcept { return description_; }
  const std::vector<Component>& components() const noexcept { return components_; }
  const std::vector<DataItem>& items() const noexcept { return items_; }
  /// The index of the item with this id, if any.
  std::optional<std::size_t> find(std::string_view id) const noexcept;
  /// The first component with this element name (e.g. "Path"), or −1.
  int find_component(std::string_view element) const noexcept;

 private:
  std::string name_, uuid_, description_;
  std::vector<Component> components_;
  std::vector<DataItem> items_;
};

/// `text` made an XML ID: letters, digits, '_' and '-' kept, anything else '_', a leading digit
/// prefixed with '_'. Any thread.
std::string xml_id(std::string_view text);

}  // namespace opencnc::connect
