#include "viscera/protocol/dds.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <string_view>

#include <dds/dds.h>

#include "viscera/common/command_line.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"
#include "viscera/protocol/streams.hpp"

#include "envelope.h"

namespace viscera::protocol {

namespace {
int32_t check(int32_t rc, const char* what) {
  if (rc < 0) throw DdsError(what, rc);
  return rc;
}

// Cyclone logs why a call failed (a missing certificate, a permissions document that does not
// verify) on the calling thread before it returns the bare code. While a viscera call creates an
// entity, its thread keeps that line for the error instead of printing it: one line per failure.
// Everything else Cyclone logs goes to stderr as before.
thread_local bool t_capturing = false;
thread_local std::string t_cyclone_said;
thread_local bool t_cyclone_error = false;  // t_cyclone_said is an error, not a warning

void log_sink(void*, const dds_log_data_t* d) {
  std::string_view m(d->message, d->size);
  if (t_capturing && (d->priority & (DDS_LC_FATAL | DDS_LC_ERROR | DDS_LC_WARNING)) != 0) {
    while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.remove_suffix(1);
    // Why it failed is an error; a warning (a deprecated element) is kept only until one comes.
    const bool error = (d->priority & (DDS_LC_FATAL | DDS_LC_ERROR)) != 0;
    if (t_cyclone_said.empty() || (error && !t_cyclone_error)) t_cyclone_said = m;
    t_cyclone_error = t_cyclone_error || error;
    return;
  }
  std::fprintf(stderr, "DDS: %.*s%s", static_cast<int>(m.size()), m.data(), m.empty() || m.back() != '\n' ? "\n" : "");
}

/// Runs `create` with Cyclone's errors kept; a failure throws DdsError naming `what`, Cyclone's
/// reason and, where security refused it, what the identity's permissions must grant.
int32_t created(const std::function<int32_t()>& create, const std::string& what, const std::string& refused_by_security = {}) {
  static std::once_flag sink;
  std::call_once(sink, [] { dds_set_log_sink(log_sink, nullptr); });
  t_capturing = true;
  t_cyclone_said.clear();
  t_cyclone_error = false;
  const int32_t rc = create();
  t_capturing = false;
  if (rc >= 0) return rc;
  std::string detail = rc == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY ? refused_by_security : std::string();
  if (!t_cyclone_said.empty()) detail += (detail.empty() ? "" : "; ") + common::printable(t_cyclone_said, 300);
  throw DdsError(what, rc, detail);
}

std::string shown_partition(const std::string& partition) { return partition.empty() ? "the default partition" : "station '" + partition + "'"; }

dds_qos_t* qos_for(Stream s, const std::string& partition, const std::string& role = {}) {
  dds_qos_t* q = dds_create_qos();
  if (!role.empty()) dds_qset_userdata(q, role.data(), role.size());
  if (!partition.empty()) {
    const char* names[] = {partition.c_str()};
    dds_qset_partition(q, 1, names);
  }
  const StreamInfo& info = stream_info(s);
  if (info.reliability == Reliability::best_effort)
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  else  // a writer blocks at most this long on a full history: long only where every sample must arrive (keep all)
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, info.depth == 0 ? DDS_SECS(10) : DDS_MSECS(100));
  if (info.depth == 0)
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  else
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, info.depth);
  dds_qset_durability(q, info.durability == Durability::transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  // What a late joiner gets: Cyclone keeps the durability service's history for it (default: the
  // last sample), not the writer's: the surface's whole message and the patches after it.
  if (info.durability == Durability::transient_local && info.depth > 0)
    dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, info.depth, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  // A client that dies or goes silent loses its liveliness within this lease.
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(kLivelinessLease.count()));
  return q;
}
}  // namespace

DdsError::DdsError(const std::string& what, int32_t code, const std::string& detail)
    : std::runtime_error("DDS: " + what + ": " + dds_strretcode(code) + (detail.empty() ? "" : ": " + detail)) {}

const char* topic_name(Stream s) { return stream_info(s).topic; }

const char* stream_name(Stream s) { return topic_name(s) + std::strlen("viscera_"); }

bool parse_stream(const std::string& name, Stream* out) {
  for (int k = 0; k < kStreamCount; ++k)
    if (name == stream_name(static_cast<Stream>(k))) {
      *out = static_cast<Stream>(k);
      return true;
    }
  return false;
}

Participant::Participant(std::uint32_t domain_id, std::string partition, std::string role)
    : handle_(
          created([&] { return dds_create_participant(domain_id, nullptr, nullptr); }, "create participant (the configuration in CYCLONEDDS_URI)")),
      partition_(std::move(partition)),
      role_(std::move(role)) {}

std::string station_name_problem(const std::string& name) {
  const std::string shown = "'" + common::printable(name, 80) + "'";
  if (name.find_first_of("*?") != std::string::npos)
    return shown + " holds a DDS wildcard ('*' or '?'), which would reach other stations' partitions, live servers' too";
  if (name.size() > 64) return shown + " is longer than 64 characters";
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.')
      return shown + " holds a character other than letters, digits, '-', '_' and '.'";
  return {};
}

std::string checked_station(const std::string& name, const std::string& flag) {
  if (const std::string why = station_name_problem(name); !why.empty()) throw common::UsageError(flag + ": " + why);
  return name;
}

Participant::~Participant() { dds_delete(handle_); }

int32_t Participant::topic(Stream s) {
  int32_t& t = topics_[static_cast<int>(s)];
  if (t == 0)
    t = created([&] { return dds_create_topic(handle_, &viscera_Envelope_desc, topic_name(s), nullptr, nullptr); },
                std::string("create topic ") + topic_name(s));
  return t;
}

Writer::Writer(Participant& p, Stream s) {
  const std::unique_ptr<dds_qos_t, void (*)(dds_qos_t*)> q(qos_for(s, p.partition(), p.role()), dds_delete_qos);
  handle_ = created([&] { return dds_create_writer(p.handle(), p.topic(s), q.get(), nullptr); },
                    std::string("create writer of ") + topic_name(s) + " in " + shown_partition(p.partition()),
                    "DDS Security: this identity's permissions document does not grant publishing it");
}

Writer::~Writer() { dds_delete(handle_); }

void Writer::write(std::uint32_t source_id, std::span<const std::uint8_t> payload) {
  viscera_Envelope e{};
  e.source_id = source_id;
  e.seq = ++seq_;
  e.stamp_ns = now_ns();
  // One copy, by dds_write: the envelope points at the caller's buffer.
  e.payload._buffer = const_cast<std::uint8_t*>(payload.data());
  e.payload._length = e.payload._maximum = static_cast<std::uint32_t>(payload.size());
  e.payload._release = false;
  check(dds_write(handle_, &e), "write");
}

int Writer::matched() const {
  dds_publication_matched_status_t st{};
  dds_get_publication_matched_status(handle_, &st);
  return static_cast<int>(st.current_count);
}

std::uint64_t Writer::matched_ever() const {
  dds_publication_matched_status_t st{};
  dds_get_publication_matched_status(handle_, &st);
  return st.total_count;
}

bool Writer::wait_for_readers(std::chrono::milliseconds timeout) const {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (matched() == 0) {
    if (std::chrono::steady_clock::now() >= end) return false;
    dds_sleepfor(DDS_MSECS(5));
  }
  return true;
}

bool Writer::wait_for_settled_readers(std::chrono::milliseconds quiet, std::chrono::milliseconds timeout) const {
  const auto end = std::chrono::steady_clock::now() + timeout;
  if (!wait_for_readers(timeout)) return false;
  int count = matched();
  auto since = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - since < quiet) {
    if (std::chrono::steady_clock::now() >= end) return true;
    dds_sleepfor(DDS_MSECS(5));
    if (const int now = matched(); now != count) {
      count = now;
      since = std::chrono::steady_clock::now();
    }
  }
  return true;
}

bool Writer::wait_for_acks(std::chrono::milliseconds timeout) const {
  return dds_wait_for_acks(handle_, DDS_MSECS(timeout.count())) == DDS_RETCODE_OK;
}

Reader::Reader(Participant& p, Stream s, ReaderOptions options) {
  const std::unique_ptr<dds_qos_t, void (*)(dds_qos_t*)> q(qos_for(s, p.partition()), dds_delete_qos);
  if (options.history_depth > 0) dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, options.history_depth);
  handle_ = created([&] { return dds_create_reader(p.handle(), p.topic(s), q.get(), nullptr); },
                    std::string("create reader of ") + topic_name(s) + " in " + shown_partition(p.partition()),
                    "DDS Security: this identity's permissions document does not grant subscribing to it");
  waitset_ = check(dds_create_waitset(p.handle()), "create waitset");
  condition_ = check(dds_create_readcondition(handle_, DDS_ANY_STATE), "create read condition");
  check(dds_waitset_attach(waitset_, condition_, handle_), "attach");
}

Reader::~Reader() {
  dds_waitset_detach(waitset_, condition_);
  dds_delete(condition_);
  dds_delete(waitset_);
  dds_delete(handle_);
}

int Reader::take(const std::function<void(const Received&)>& f) {
  constexpr int kMax = 64;
  void* samples[kMax] = {nullptr};
  dds_sample_info_t infos[kMax];
  int total = 0;
  for (;;) {
    const int32_t n = dds_take(handle_, samples, infos, kMax, kMax);  // loaned samples
    if (n <= 0) break;
    for (int32_t k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      const auto* e = static_cast<const viscera_Envelope*>(samples[k]);
      const std::uint64_t writer = infos[k].publication_handle;
      const Sender s = sender_of(writer);
      f({e->source_id, e->seq, e->stamp_ns, {e->payload._buffer, e->payload._length}, writer, s.participant, s.identity});
      ++total;
    }
    dds_return_loan(handle_, samples, n);
    if (n < kMax) break;
  }
  return total;
}

Reader::Sender Reader::sender_of(std::uint64_t writer) {
  if (const auto it = senders_.find(writer); it != senders_.end()) return it->second;
  Sender s{0, 0};
  if (dds_builtintopic_endpoint_t* ep = dds_get_matched_publication_data(handle_, writer)) {
    s.participant = 1469598103934665603ull;  // FNV-1a over the participant's 16-byte GUID
    for (const unsigned char b : ep->participant_key.v) s.participant = (s.participant ^ b) * 1099511628211ull;
    for (int k = 0; k < 6; ++k) s.identity = (s.identity << 8) | ep->participant_key.v[k];  // the GUID prefix's first 6 bytes
    dds_builtintopic_free_endpoint(ep);
  }
  if (s.participant == 0) return s;  // not known (yet): asked again next time
  if (senders_.size() >= 4096) senders_.clear();  // writers come and go; keep the cache small
  senders_.emplace(writer, s);
  return s;
}

bool security_configured() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri == nullptr) return false;
  // Cyclone reads a list of files (file://PATH) and inline XML, separated by commas; element
  // names are not case-sensitive. Security is configured by a <Security> (or older <DDSSecurity>)
  // element in any of them.
  const auto lower = [](std::string t) {
    for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return t;
  };
  const auto has_security = [](const std::string& xml) {
    return xml.find("<security>") != std::string::npos || xml.find("<security ") != std::string::npos ||
           xml.find("<ddssecurity") != std::string::npos;
  };
  std::stringstream items(uri);
  for (std::string item; std::getline(items, item, ',');) {
    std::string text = item;
    if (item.rfind("file://", 0) == 0) {
      try {
        text = common::read_text_file(item.substr(7), 1u << 20);  // a regular file, bounded: never a FIFO read without end
      } catch (const common::InputError&) {
        continue;  // Cyclone itself names a configuration it cannot read
      }
    }
    for (auto c = text.find("<!--"); c != std::string::npos; c = text.find("<!--", c)) {  // comments
      const auto end = text.find("-->", c);
      text.erase(c, end == std::string::npos ? std::string::npos : end + 3 - c);
    }
    if (has_security(lower(text))) return true;
  }
  return false;
}

PartitionDiscovery::PartitionDiscovery(Participant& p, Stream s, std::string role)
    : reader_(check(dds_create_reader(p.handle(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr), "create discovery reader")),
      topic_(topic_name(s)),
      role_(std::move(role)) {}

PartitionDiscovery::~PartitionDiscovery() { dds_delete(reader_); }

std::vector<std::string> PartitionDiscovery::take_new() {
  constexpr int kMax = 64;
  std::vector<std::string> out;
  void* samples[kMax] = {nullptr};
  dds_sample_info_t infos[kMax];
  for (;;) {
    const int32_t n = dds_take(reader_, samples, infos, kMax, kMax);  // loaned samples
    if (n <= 0) break;
    for (int32_t k = 0; k < n; ++k) {
      const auto* w = static_cast<const dds_builtintopic_endpoint_t*>(samples[k]);
      if (!infos[k].valid_data || w->topic_name == nullptr || topic_ != w->topic_name) continue;
      if (!role_.empty()) {
        void* data = nullptr;
        size_t size = 0;
        const bool has = w->qos != nullptr && dds_qget_userdata(w->qos, &data, &size);
        const bool match = has && std::string(static_cast<const char*>(data), size) == role_;
        dds_free(data);
        if (!match) continue;
      }
      std::uint32_t count = 0;
      char** names = nullptr;
      std::vector<std::string> partitions;
      if (w->qos != nullptr && dds_qget_partition(w->qos, &count, &names)) {
        for (std::uint32_t j = 0; j < count; ++j) {
          partitions.emplace_back(names[j]);
          dds_free(names[j]);
        }
        dds_free(static_cast<void*>(names));
      }
      if (partitions.empty()) partitions.emplace_back();  // the default partition
      for (auto& name : partitions)
        if (seen_.insert(name).second) out.push_back(std::move(name));
    }
    dds_return_loan(reader_, samples, n);
    if (n < kMax) break;
  }
  return out;
}

bool Reader::wait(std::chrono::nanoseconds timeout) { return dds_waitset_wait(waitset_, nullptr, 0, timeout.count()) > 0; }

int Reader::alive_writers() const {
  dds_liveliness_changed_status_t st{};
  dds_get_liveliness_changed_status(handle_, &st);
  return static_cast<int>(st.alive_count);
}

void Reader::on_alive_writers_changed(std::function<void(int)> f) {
  on_alive_ = std::move(f);
  dds_listener_t* l = dds_create_listener(this);
  dds_lset_liveliness_changed(l, [](dds_entity_t, const dds_liveliness_changed_status_t st, void* arg) {
    static_cast<Reader*>(arg)->on_alive_(static_cast<int>(st.alive_count));
  });
  const dds_return_t rc = dds_set_listener(handle_, l);
  dds_delete_listener(l);
  check(rc, "set listener");
}

std::int64_t now_ns() { return dds_time(); }

}  // namespace viscera::protocol
