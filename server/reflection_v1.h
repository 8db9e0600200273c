// gRPC server reflection, version 1 (grpc.reflection.v1), beside the v1alpha that gRPC 1.51's
// plugin serves: newer tools (grpcurl, grpcui, Postman) ask for v1 first. Answers from the
// descriptors compiled into the server (protobuf's generated pool), as the plugin does: the file
// that defines a name or a symbol with every file it imports, the extensions of a type, and the
// services the server offers. Like health, it needs no token: it reads nothing of the world.
#pragma once

#include <string>
#include <vector>

#include "grpc/reflection/v1/reflection.grpc.pb.h"

namespace tumble::server {

class ReflectionV1 final : public grpc::reflection::v1::ServerReflection::Service {
 public:
  explicit ReflectionV1(std::vector<std::string> services) : services_(std::move(services)) {}

  grpc::Status ServerReflectionInfo(
      grpc::ServerContext* context,
      grpc::ServerReaderWriter<grpc::reflection::v1::ServerReflectionResponse,
                               grpc::reflection::v1::ServerReflectionRequest>* stream) override;

 private:
  std::vector<std::string> services_;
};

}  // namespace tumble::server
