// The checks every request passes before and after its route (docs/api.md, "Errors"):
// authentication, body framing and size, Range on result files, and the problem+json
// answers for requests no route takes (404, 405 with Allow).
#pragma once

#include <optional>
#include <string>

#include <httplib.h>

#include "server_config.h"

namespace rdm::server {

// Runs before the body is read (and instead of `100 Continue`): Handled when it refused.
httplib::Server::HandlerResponse preRoute(const ServerConfig& config, const httplib::Request& req,
                                          httplib::Response& res);

// Whether an Authorization field value carries `token` as a bearer token (constant time).
bool bearerMatches(const std::string& header, const std::string& token);

// True for the routes whose bodies are result files and honour one Range.
bool isResultFile(const std::string& path);

// Applies a single `bytes=` range to a 200 result-file response: 206 with Content-Range, or
// 416 problem+json with `Content-Range: bytes */SIZE`. Other ranges and routes are ignored
// (RFC 9110 14.2).
void applyRange(const httplib::Request& req, httplib::Response& res,
                const std::optional<std::string>& range);

// httplib's error handler: problem+json for bodiless errors, 405 + Allow for a known path with
// another method, 204 + Allow for OPTIONS.
httplib::Server::HandlerResponse routeError(const httplib::Request& req, httplib::Response& res);

}  // namespace rdm::server
