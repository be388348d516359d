// SPDX-License-Identifier: GPL-3.0-or-later
// Publishing the agent's observations to an MQTT broker with libmosquitto.
//
// Why our own queue and not libmosquitto's: the library keeps unacknowledged QoS 1 messages and
// sends them again after a reconnection, but it neither bounds them nor says what it dropped. Here
// each batch stays queued until its PUBACK; on a lost connection the client is destroyed (its own
// in-flight copies with it) and every unacknowledged batch is sent again on the next one, so each
// batch is in flight once at a time. A broker that received a batch whose PUBACK was lost receives
// it twice: subscribers drop what they have by its sequence numbers.
#include "opencnc/connect/mqtt_publisher.hpp"

#include <fmt/format.h>
#include <mosquitto.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace opencnc::connect {

namespace {

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// libmosquitto's global state, initialised once for the process.
void init_library() {
  static const int once = [] { return mosquitto_lib_init(); }();
  (void)once;
}

}  // namespace

std::optional<MqttAddress> parse_mqtt_url(std::string_view url, std::string* error) {
  auto fail = [&](std::string why) -> std::optional<MqttAddress> {
    if (error) *error = std::move(why);
    return std::nullopt;
  };
  constexpr std::string_view scheme = "mqtt://";
  if (!url.starts_with(scheme)) return fail(fmt::format("'{}': expected mqtt://HOST[:PORT]", url));
  std::string_view rest = url.substr(scheme.size());
  if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
  MqttAddress a;
  std::string_view host = rest, port;
  if (rest.starts_with('[')) {  // [::1]:1883
    const auto close = rest.find(']');
    if (close == std::string_view::npos)
      return fail(fmt::format("'{}': an IPv6 address without its ']'", url));
    host = rest.substr(1, close - 1);
    const std::string_view after = rest.substr(close + 1);
    if (!after.empty() && after.front() != ':')
      return fail(fmt::format("'{}': expected ':PORT' after ']'", url));
    if (!after.empty()) port = after.substr(1);
  } else if (const auto colon = rest.rfind(':'); colon != std::string_view::npos) {
    host = rest.substr(0, colon);
    port = rest.substr(colon + 1);
    if (port.empty()) return fail(fmt::format("'{}': no port after ':'", url));
  }
  if (!port.empty()) {
    auto [p, ec] = std::from_chars(port.data(), port.data() + port.size(), a.port);
    if (ec != std::errc{} || p != port.data() + port.size() || a.port < 1 || a.port > 65535)
      return fail(fmt::format("'{}': the port must be a number from 1 to 65535", url));
  }
  if (host.empty()) return fail(fmt::format("'{}': no host", url));
  a.host = std::string(host);
  return a;
}

std::string mqtt_topic(std::string_view prefix, std::string_view kind, std::string_view uuid) {
  return fmt::format("{}/{}/{}", prefix, kind, uuid);
}

MqttPublisher::MqttPublisher(const Agent& agent, MqttOptions options)
    : agent_(agent), options_(std::move(options)) {
  if (options_.keepalive_s < 5 || options_.keepalive_s > 65535)
    throw std::invalid_argument("mqtt: the keep-alive must be 5 to 65535 s");
  if (options_.queue_limit == 0 || options_.batch_size == 0)
    throw std::invalid_argument("mqtt: the queue limit and the batch size must be at least 1");
  init_library();
  const std::string& uuid = agent_.model().uuid();
  sample_topic_ = mqtt_topic(options_.topic_prefix, "Sample", uuid);
  current_topic_ = mqtt_topic(options_.topic_prefix, "Current", uuid);
  probe_topic_ = mqtt_topic(options_.topic_prefix, "Probe", uuid);
  availability_topic_ = mqtt_topic(options_.topic_prefix, "Availability", uuid);
  next_ = agent_.next_sequence();
  // Everything before the publisher started is in the retained current state, not in the samples.
  current_published_at_ = 0;
}

MqttPublisher::~MqttPublisher() {
  stop(0);
}

void MqttPublisher::start() {
  if (thread_.joinable()) return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void MqttPublisher::stop(int drain_ms) {
  if (!thread_.joinable()) return;
  const std::int64_t until = now_ms() + drain_ms;
  while (now_ms() < until) {
    {
      std::lock_guard lock(mutex_);
      if (pending_.empty() && next_ >= agent_.next_sequence()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stopping_ = true;
  wake_.notify_all();
  thread_.join();
  std::unique_lock lock(mutex_);
  if (client_ != nullptr && connected_) {
    // A clean disconnect does not send the will: say it ourselves, and wait for it to leave.
    int mid = 0;
    const char* word = "UNAVAILABLE";
    mosquitto_publish(client_, &mid, availability_topic_.c_str(),
                      static_cast<int>(std::char_traits<char>::length(word)), word, 1, true);
    lock.unlock();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    lock.lock();
    mosquitto_disconnect(client_);
  }
  lock.unlock();
  drop_client();
}

MqttStats MqttPublisher::stats() const {
  std::lock_guard lock(mutex_);
  MqttStats s = stats_;
  s.connected = connected_;
  s.dropped = dropped_;
  s.queued = queued_;
  s.next_sequence = next_;
  return s;
}

void MqttPublisher::on_connect(struct mosquitto*, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  std::lock_guard lock(p->mutex_);
  if (rc != 0) {
    p->lost_ = true;
    p->stats_.last_error = fmt::format("the broker refused the connection: {}", mosquitto_connack_string(rc));
  } else {
    p->connected_ = true;
    p->just_connected_ = true;
    ++p->stats_.connects;
    p->backoff_ms_ = 0;
  }
  p->wake_.notify_all();
}

void MqttPublisher::on_disconnect(struct mosquitto*, void* self, int rc) {
  auto* p = static_cast<MqttPublisher*>(self);
  std::lock_guard lock(p->mutex_);
  if (rc != 0) p->stats_.last_error = fmt::format("the connection was lost: {}", mosquitto_strerror(rc));
  p->connected_ = false;
  p->lost_ = true;
  p->wake_.notify_all();
}

void MqttPublisher::on_publish(struct mosquitto*, void* self, int mid) {
  auto* p = static_cast<MqttPublisher*>(self);
  std::lock_guard lock(p->mutex_);
  auto it =
      std::find_if(p->pending_.begin(), p->pending_.end(), [&](const Batch& b) { return b.mid == mid; });
  if (it == p->pending_.end()) return;  // the availability or the current state
  ++p->stats_.batches_acked;
  p->stats_.observations_acked += it->count;
  p->queued_ -= it->count;
  p->pending_.erase(it);
}

void MqttPublisher::connect_client() {
  // Called with the mutex held.
  client_ = mosquitto_new(
      fmt::format("opencnc-{}-{}", agent_.model().uuid(), agent_.options().instance_id).c_str(), true, this);
  if (client_ == nullptr) return;
  const char* will = "UNAVAILABLE";
  mosquitto_will_set(client_, availability_topic_.c_str(),
                     static_cast<int>(std::char_traits<char>::length(will)), will, 1, true);
  mosquitto_connect_callback_set(client_, &MqttPublisher::on_connect);
  mosquitto_disconnect_callback_set(client_, &MqttPublisher::on_disconnect);
  mosquitto_publish_callback_set(client_, &MqttPublisher::on_publish);
  // One batch in flight is enough on loopback, more keep a distant broker's line full.
  mosquitto_max_inflight_messages_set(client_, 32);
  lost_ = false;
  int rc = mosquitto_connect_async(client_, options_.broker.host.c_str(), options_.broker.port,
                                   options_.keepalive_s);
  if (rc == MOSQ_ERR_SUCCESS) rc = mosquitto_loop_start(client_);
  if (rc != MOSQ_ERR_SUCCESS) {
    lost_ = true;
    stats_.last_error = fmt::format("cannot connect to {}:{}: {}", options_.broker.host, options_.broker.port,
                                    rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc));
  }
}

void MqttPublisher::drop_client() {
  struct mosquitto* c = nullptr;
  {
    std::lock_guard lock(mutex_);
    c = client_;
    client_ = nullptr;
    connected_ = false;
    for (auto& b : pending_) b.mid = -1;  // sent again on the next connection
  }
  if (c != nullptr) {
    mosquitto_disconnect(c);
    mosquitto_loop_stop(c, true);
    mosquitto_destroy(c);
  }
}

namespace {

/// Two gaps as one: the first's start to the second's end (they are consecutive or adjacent).
Gap merge(const Gap& a, const Gap& b) {
  if (a.count == 0) return b;
  if (b.count == 0) return a;
  return Gap{std::min(a.from, b.from), std::max(a.to, b.to), a.count + b.count};
}

}  // namespace

void MqttPublisher::queue_new_observations() {
  // With the mutex held: read the agent's new observations into batches. New observations join
  // the last batch while it is unsent and not full: after an outage the backlog leaves in a few
  // full messages rather than one per poll (a broker queues a bounded number of messages for each
  // subscriber — mosquitto 1000 by default — and drops the rest).
  const std::size_t most = std::min(options_.batch_size, options_.queue_limit);  // a batch's size
  while (true) {
    Batch* open = !pending_.empty() && pending_.back().mid == -1 && gap_.count == 0 &&
                          pending_.back().count < most
                      ? &pending_.back()
                      : nullptr;
    std::uint64_t first = 0;
    std::vector<Observation> batch = agent_.observations(next_, open ? most - open->count : most, &first);
    if (first > next_) {  // the agent's buffer turned over before we read these
      dropped_ += first - next_;
      gap_ = merge(gap_, Gap{next_, first - 1, first - next_});
      open = nullptr;  // the gap goes with the next batch
    }
    if (batch.empty()) {
      next_ = std::max(next_, first);
      return;
    }
    next_ = batch.back().sequence + 1;
    if (open != nullptr) {
      open->last = batch.back().sequence;
      open->count += batch.size();
      queued_ += batch.size();
      open->observations.insert(open->observations.end(), std::make_move_iterator(batch.begin()),
                                std::make_move_iterator(batch.end()));
      continue;
    }
    Batch b;
    b.first = batch.front().sequence;
    b.last = batch.back().sequence;
    b.count = batch.size();
    b.observations = std::move(batch);
    b.gap = gap_;
    gap_ = Gap{};
    queued_ += b.count;
    pending_.push_back(std::move(b));
    // Bounded while the broker is away: the oldest unsent batches go, and the batch after them
    // carries the whole gap to the subscribers.
    while (queued_ > options_.queue_limit && pending_.size() > 1 && pending_.front().mid == -1) {
      Batch old = std::move(pending_.front());
      pending_.pop_front();
      dropped_ += old.count;
      queued_ -= old.count;
      pending_.front().gap = merge(merge(old.gap, Gap{old.first, old.last, old.count}), pending_.front().gap);
    }
  }
}

void MqttPublisher::publish_pending() {
  // With the mutex held and a connection.
  for (auto& b : pending_) {
    if (b.mid != -1) continue;
    int mid = 0;
    const std::string payload =
        sample_json(agent_.model(), agent_.options(), b.observations, b.gap, dropped_);
    const int rc = mosquitto_publish(client_, &mid, sample_topic_.c_str(), static_cast<int>(payload.size()),
                                     payload.data(), 1, false);
    if (rc != MOSQ_ERR_SUCCESS) return;  // the connection went: the loop notices
    b.mid = mid;
  }
}

void MqttPublisher::publish_current(bool force) {
  // With the mutex held and a connection: the retained state a new subscriber starts from.
  const std::int64_t now = now_ms();
  const std::uint64_t next = agent_.next_sequence();
  if (!force && (now < current_due_ms_ || next == current_published_at_)) return;
  const std::string payload =
      current_json(agent_.model(), agent_.options(), agent_.snapshot(), next, agent_.progress());
  if (mosquitto_publish(client_, nullptr, current_topic_.c_str(), static_cast<int>(payload.size()),
                        payload.data(), 1, true) == MOSQ_ERR_SUCCESS) {
    current_published_at_ = next;
    current_due_ms_ = now + options_.current_every_ms;
  }
}

void MqttPublisher::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    queue_new_observations();
    const std::int64_t now = now_ms();
    if (client_ == nullptr && now >= reconnect_at_ms_) {
      connect_client();
    } else if (client_ != nullptr && lost_) {
      lock.unlock();
      drop_client();
      lock.lock();
      backoff_ms_ =
          backoff_ms_ == 0 ? options_.reconnect_min_ms : std::min(backoff_ms_ * 2, options_.reconnect_max_ms);
      reconnect_at_ms_ = now_ms() + backoff_ms_;
      continue;
    }
    if (client_ != nullptr && connected_) {
      if (just_connected_) {
        just_connected_ = false;
        const std::string probe = probe_json(agent_.model(), agent_.options(), options_.hmi_url);
        mosquitto_publish(client_, nullptr, probe_topic_.c_str(), static_cast<int>(probe.size()),
                          probe.data(), 1, true);
        const char* word = "AVAILABLE";
        mosquitto_publish(client_, nullptr, availability_topic_.c_str(),
                          static_cast<int>(std::char_traits<char>::length(word)), word, 1, true);
        publish_current(true);
      }
      publish_pending();
      publish_current(false);
    }
    wake_.wait_for(lock, std::chrono::milliseconds(options_.poll_ms));
  }
}

}  // namespace opencnc::connect
