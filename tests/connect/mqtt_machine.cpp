// SPDX-License-Identifier: GPL-3.0-or-later
// A machine for the MQTT tests: an agent of `profile` named `name`, its status moving every 5 ms,
// published to 127.0.0.1:`port` until the process is killed.
//   mqtt_machine PROFILE NAME PORT KEEPALIVE_S
#include <fmt/format.h>

#include <chrono>
#include <thread>

#include "mqtt_rig.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/mqtt_publisher.hpp"

int main(int argc, char** argv) {
  using namespace opencnc;
  if (argc != 5) {
    fmt::print(stderr, "usage: mqtt_machine PROFILE NAME PORT KEEPALIVE_S\n");
    return 2;
  }
  const auto load = config::load_profile(argv[1]);
  if (!load.ok()) return 1;
  connect::AgentOptions ao;
  ao.device_name = argv[2];
  auto agent = connect::Agent::for_profile(*load.profile, ao);
  connect::MqttOptions mo;
  mo.broker = connect::MqttAddress{"127.0.0.1", std::atoi(argv[3])};
  mo.keepalive_s = std::atoi(argv[4]);
  connect::MqttPublisher publisher(*agent, mo);
  publisher.start();
  for (std::uint64_t i = 0;; ++i) {
    agent->observe(connect::test::moving_status(i), static_cast<std::int64_t>(i) * 5000);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}
