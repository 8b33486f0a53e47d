#include "long_poll.h"

#include <cctype>

namespace rdm::server {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kCheckSeconds = 0.05;  // the longest a finished wait stays parked

// A decimal in [lo, hi], or -1.
int smallInt(const std::string& text, int lo, int hi) {
  if (text.empty() || text.size() > 3) return -1;
  int v = 0;
  for (char c : text) {
    if (!std::isdigit(uint8_t(c))) return -1;
    v = v * 10 + (c - '0');
  }
  return v >= lo && v <= hi ? v : -1;
}

bool plainId(const std::string& id) {
  if (id.empty() || id.size() > 64) return false;
  for (char c : id) {
    if (!std::isalnum(uint8_t(c)) && c != '-' && c != '_') return false;
  }
  return true;
}

}  // namespace

std::optional<LongPoll> parseLongPoll(const std::string& head) {
  static const std::string kPrefix = "GET /v1/jobs/";
  if (head.compare(0, kPrefix.size(), kPrefix) != 0) return std::nullopt;
  const size_t target_end = head.find(' ', kPrefix.size());
  const size_t query = head.find('?', kPrefix.size());
  if (target_end == std::string::npos || query == std::string::npos || query > target_end)
    return std::nullopt;
  LongPoll poll;
  poll.job_id = head.substr(kPrefix.size(), query - kPrefix.size());
  if (!plainId(poll.job_id)) return std::nullopt;
  bool has_wait = false;
  for (size_t pos = query + 1; pos < target_end;) {
    size_t amp = head.find('&', pos);
    if (amp == std::string::npos || amp > target_end) amp = target_end;
    const size_t eq = head.find('=', pos);
    if (eq != std::string::npos && eq < amp) {
      const std::string key = head.substr(pos, eq - pos);
      const std::string value = head.substr(eq + 1, amp - eq - 1);
      if (key == "wait") {
        if (has_wait) return std::nullopt;  // a repeated parameter: the worker decides
        has_wait = true;
        poll.wait_s = smallInt(value, 1, 30);
        if (poll.wait_s < 0) return std::nullopt;
        poll.wait_value_pos = eq + 1, poll.wait_value_len = value.size();
      } else if (key == "passes") {
        poll.passes = smallInt(value, 1, 16);
        if (poll.passes < 0) return std::nullopt;
      }
    }
    pos = amp + 1;
  }
  if (!has_wait) return std::nullopt;
  return poll;
}

void endLongPoll(PendingRequest& request, const LongPoll& poll) {
  request.bytes.replace(poll.wait_value_pos, poll.wait_value_len, "0");
}

std::optional<std::string> headerValue(const std::string& head, const std::string& name) {
  size_t pos = head.find('\n');
  while (pos != std::string::npos && pos + 1 < head.size()) {
    const size_t start = pos + 1;
    const size_t eol = head.find('\n', start);
    const size_t end = eol == std::string::npos ? head.size() : eol;
    if (end - start <= 1) return std::nullopt;  // the blank line: the body follows
    bool match = end - start > name.size();
    for (size_t i = 0; match && i < name.size(); ++i)
      match = std::tolower(uint8_t(head[start + i])) == name[i];
    if (match) {
      std::string value = head.substr(start + name.size(), end - start - name.size());
      value.erase(0, value.find_first_not_of(" \t"));
      value.erase(value.find_last_not_of(" \t\r") + 1);
      return value;
    }
    pos = eol;
  }
  return std::nullopt;
}

LongPollParker::LongPollParker(size_t max_parked, WaitsOver over, Release release)
    : max_parked_(max_parked), over_(std::move(over)), release_(std::move(release)) {}

LongPollParker::~LongPollParker() {
  stop();
}

void LongPollParker::start() {
  thread_ = std::thread([this] { loop(); });
}

bool LongPollParker::park(PendingRequest& request, const LongPoll& poll) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_ || parked_.size() >= max_parked_) return false;
  parked_.push_back({std::move(request), poll, Clock::now() + std::chrono::seconds(poll.wait_s)});
  changed_.notify_one();
  return true;
}

size_t LongPollParker::parked() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return parked_.size();
}

void LongPollParker::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  for (Parked& p : takeOver(true)) {
    endLongPoll(p.request, p.poll);
    release_(p.request);
  }
}

std::vector<LongPollParker::Parked> LongPollParker::takeOver(bool all) {
  std::vector<std::pair<std::string, int>> waits;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!all) changed_.wait(lock, [&] { return stopping_ || !parked_.empty(); });
    if (all || stopping_) {
      std::vector<Parked> out;
      out.swap(parked_);
      return out;
    }
    for (const Parked& p : parked_) waits.emplace_back(p.poll.job_id, p.poll.passes);
  }
  // Entries past waits.size() were parked meanwhile: the next round checks them. Only this
  // thread removes entries, so the first waits.size() are the ones asked about.
  const std::vector<bool> over = over_(waits, kCheckSeconds);
  std::vector<Parked> ready;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  size_t kept = 0;
  for (size_t i = 0; i < parked_.size(); ++i) {
    const bool done = i < over.size() && (over[i] || now >= parked_[i].deadline);
    if (done || stopping_) {
      ready.push_back(std::move(parked_[i]));
    } else {
      if (kept != i) parked_[kept] = std::move(parked_[i]);
      ++kept;
    }
  }
  parked_.resize(kept);
  return ready;
}

void LongPollParker::loop() {
  while (true) {
    std::vector<Parked> ready = takeOver(false);
    for (Parked& p : ready) {
      endLongPoll(p.request, p.poll);
      release_(p.request);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
  }
}

}  // namespace rdm::server
