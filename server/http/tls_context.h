// HTTPS with the gRPC port's certificate: a PEM certificate chain and private key, as
// --tls-cert and --tls-key hold them, loaded into an OpenSSL server context.
#ifndef MOTIONDB_SERVER_HTTP_TLS_CONTEXT_H_
#define MOTIONDB_SERVER_HTTP_TLS_CONTEXT_H_

#include <openssl/ssl.h>

#include <string>

#include "absl/status/status.h"

namespace motiondb::server {

// The chain's first certificate is the server's, the others its intermediates. INVALID_ARGUMENT
// when either does not parse or the key is not the certificate's.
absl::Status LoadPemIntoContext(const std::string& cert_chain_pem, const std::string& key_pem,
                                SSL_CTX& context);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_TLS_CONTEXT_H_
