// Why the server could not listen on an address. gRPC's BuildAndStart only says that it failed;
// a user who started a second server on a taken port needs to read "address already in use".
#pragma once

#include <string>

namespace tumble::server {

// Binds a plain socket to `address` ("host:port", "[v6]:port") the way gRPC would and returns
// the system's reason for refusing it ("address already in use"), or a general sentence when
// the plain bind succeeds (the address is then free again) or the address cannot be parsed.
std::string explain_bind_failure(const std::string& address);

}  // namespace tumble::server
