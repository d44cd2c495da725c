#include "server/http/tls_context.h"

#include <openssl/err.h>
#include <openssl/pem.h>

#include <memory>

namespace motiondb::server {
namespace {

struct BioFree {
  void operator()(BIO* bio) const { BIO_free(bio); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

Bio ReadOnlyBio(const std::string& pem) {
  return Bio(BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size())));
}

}  // namespace

absl::Status LoadPemIntoContext(const std::string& cert_chain_pem, const std::string& key_pem,
                                SSL_CTX& context) {
  const Bio certs = ReadOnlyBio(cert_chain_pem);
  X509* leaf = certs ? PEM_read_bio_X509(certs.get(), nullptr, nullptr, nullptr) : nullptr;
  const bool leaf_used = leaf != nullptr && SSL_CTX_use_certificate(&context, leaf) == 1;
  X509_free(leaf);  // the context holds its own reference
  if (!leaf_used) return absl::InvalidArgumentError("--tls-cert holds no usable PEM certificate");
  // The rest of the chain; the context takes ownership of each.
  while (X509* intermediate = PEM_read_bio_X509(certs.get(), nullptr, nullptr, nullptr)) {
    if (SSL_CTX_add_extra_chain_cert(&context, intermediate) != 1) {
      X509_free(intermediate);
      return absl::InvalidArgumentError("--tls-cert: a chain certificate could not be added");
    }
  }
  ERR_clear_error();  // reading past the last certificate leaves a "no start line" error
  const Bio key_bio = ReadOnlyBio(key_pem);
  EVP_PKEY* key =
      key_bio ? PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, nullptr) : nullptr;
  const bool key_used = key != nullptr && SSL_CTX_use_PrivateKey(&context, key) == 1;
  EVP_PKEY_free(key);
  if (!key_used || SSL_CTX_check_private_key(&context) != 1) {
    ERR_clear_error();
    return absl::InvalidArgumentError(
        "--tls-key holds no PEM private key of --tls-cert's certificate");
  }
  return absl::OkStatus();
}

}  // namespace motiondb::server
