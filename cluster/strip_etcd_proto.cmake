# cmake -DIN=FILE.proto -DOUT=FILE.proto -P strip_etcd_proto.cmake
#
# Copies one of etcd's .proto files without what only its Go build uses: the gogoproto import
# and options (Go code generation) and the google.api.http options with their import (etcd's
# grpc-gateway). Messages, fields and services are untouched, so the C++ stubs speak the same
# wire format and method names as etcd's own clients.
file(READ "${IN}" text)
string(REGEX REPLACE "import \"(gogoproto/gogo|google/api/annotations)\\.proto\";" "" text "${text}")
string(REGEX REPLACE "option \\(gogoproto\\.[a-z_]+\\) = [a-z]+;" "" text "${text}")
# An http option may hold one level of braces (additional_bindings).
string(REGEX REPLACE "option \\(google\\.api\\.http\\) = {([^{}]|{[^{}]*})*};" "" text "${text}")
if(text MATCHES "gogoproto|google\\.api")
  message(FATAL_ERROR "${IN}: an option of gogoproto or google.api is left; extend "
                      "cluster/strip_etcd_proto.cmake")
endif()
file(WRITE "${OUT}" "${text}")
