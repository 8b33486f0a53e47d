// Request / response helpers shared by the route handlers.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <variant>

#include <httplib.h>

#include <nlohmann/json.hpp>

#include "problem.h"
#include "rdm/base/status.h"

namespace rdm::server {

// A route body: returns a Problem to send instead of whatever it put in `res`.
using ApiHandler =
    std::function<std::optional<Problem>(const httplib::Request&, httplib::Response&)>;
// Wraps an ApiHandler into an httplib handler that writes problems as problem+json.
httplib::Server::Handler wrap(ApiHandler handler);

// Parses the body as JSON in linear time (rdm/base/json_parse.h); an empty body is {}. 400 on
// malformed or too deeply nested JSON, with the byte offset; 422 naming the field for a number
// out of range.
Expected<nlohmann::json> parseJsonBody(const std::string& body);

void sendJson(httplib::Response& res, const nlohmann::json& j, int status = 200);
// Sets ETag (a quoted value) and Cache-Control: no-cache; true when If-None-Match matches
// (then the response is a 304 without body and the handler should return).
bool handleEtag(const httplib::Request& req, httplib::Response& res, const std::string& etag);
std::string bodyEtag(const std::string& body);  // quoted contentHashHex of the bytes

// The route a request path takes, for logs: ids replaced by {id}, an RDM's slot by {slot} and
// level by {level} ("/v1/jobs/{id}/rdms/{slot}/{level}.exr").
std::string routeOf(const std::string& path);

// Query parameter as an integer in [lo, hi]; nullopt when absent. Problem when malformed.
std::variant<std::optional<long long>, Problem> queryInt(const httplib::Request& req,
                                                         const char* name, long long lo,
                                                         long long hi);

}  // namespace rdm::server
