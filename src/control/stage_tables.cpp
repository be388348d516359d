// SPDX-License-Identifier: GPL-3.0-or-later
// The tick's editable tables written into the channels' staging areas, and the commands naming them.
#include "opencnc/control/stage_tables.hpp"

namespace opencnc::control {

std::vector<Command> stage_tables(ServoChannels& channels, const ServoConfig& next, std::uint64_t stage_id) {
  std::vector<Command> out;
  for (int joint = 0; joint < next.joint_count && joint < motion::kMaxCompensatedJoints; ++joint) {
    const auto j = static_cast<std::size_t>(joint);
    const motion::JointCompensation& c = next.compensation.joints[j];
    if (!c.enabled) continue;
    const std::int8_t reading = channels.pitch_tables.reading[j].index.load(std::memory_order_acquire);
    const auto buffer = static_cast<std::uint8_t>(reading == 0 ? 1 : 0);
    channels.pitch_tables.joints[j][buffer] = c.pitch;
    Command stage;
    stage.id = stage_id;
    stage.kind = CommandKind::StagePitchTable;
    stage.axis = static_cast<std::int8_t>(joint);
    stage.table_buffer = buffer;
    out.push_back(stage);
  }
  if (next.edm.enabled) {
    channels.edm_conditions.conditions = next.edm.conditions;
    channels.edm_conditions.count = next.edm.condition_count;
    Command stage;
    stage.id = stage_id;
    stage.kind = CommandKind::StageEdmConditions;
    out.push_back(stage);
  }
  return out;
}

}  // namespace opencnc::control
