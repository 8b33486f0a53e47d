#include "rdm/service/metrics.h"

#include <sstream>

namespace rdm {

void Metrics::countRequest(int status) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++requests_[status];
}

void Metrics::addBakeSeconds(double s) {
  std::lock_guard<std::mutex> lock(mutex_);
  bake_seconds_ += s;
}

void Metrics::jobFinished(const std::string& result) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++finished_[result];
}

std::string Metrics::render(const JobGauges& g) const {
  std::ostringstream os;
  os.precision(17);
  auto head = [&](const char* name, const char* type, const char* help) {
    os << "# HELP " << name << " " << help << "\n# TYPE " << name << " " << type << "\n";
  };
  head("rdm_queue_depth", "gauge", "Bake jobs queued or running.");
  os << "rdm_queue_depth " << g.queue_depth << "\n";
  head("rdm_units_pending", "gauge", "Work units of admitted jobs not yet baked.");
  os << "rdm_units_pending " << g.units_pending << "\n";
  head("rdm_jobs", "gauge", "Bake jobs by state.");
  for (const auto& [state, n] : g.jobs_by_state)
    os << "rdm_jobs{state=\"" << state << "\"} " << n << "\n";
  head("rdm_rays_traced_total", "counter", "Rays traced by bake work units.");
  os << "rdm_rays_traced_total " << rays_.load() << "\n";
  std::lock_guard<std::mutex> lock(mutex_);
  head("rdm_bake_seconds_total", "counter", "Thread-seconds spent baking work units.");
  os << "rdm_bake_seconds_total " << bake_seconds_ << "\n";
  head("rdm_jobs_finished_total", "counter", "Jobs that reached a terminal state, by result.");
  for (const auto& [result, n] : finished_)
    os << "rdm_jobs_finished_total{result=\"" << result << "\"} " << n << "\n";
  head("rdm_http_requests_total", "counter", "HTTP requests answered, by status code.");
  for (const auto& [code, n] : requests_)
    os << "rdm_http_requests_total{code=\"" << code << "\"} " << n << "\n";
  return os.str();
}

}  // namespace rdm
