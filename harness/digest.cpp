// digest — SHA-256 through OpenSSL's EVP API (see digest.hpp). A failure of the
// library itself (out of memory) throws: no caller can go on without a digest.
#include "harness/digest.hpp"

#include <openssl/evp.h>

#include <stdexcept>

namespace autumn {

struct Sha256::Ctx {
  EVP_MD_CTX* md = EVP_MD_CTX_new();
  ~Ctx() { EVP_MD_CTX_free(md); }
};

Sha256::Sha256() : ctx_(std::make_unique<Ctx>()) {
  if (!ctx_->md || EVP_DigestInit_ex(ctx_->md, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 is not available (libcrypto)");
}

Sha256::~Sha256() = default;

void Sha256::update(std::string_view bytes) {
  if (EVP_DigestUpdate(ctx_->md, bytes.data(), bytes.size()) != 1) throw std::runtime_error("SHA-256 update failed");
}

void Sha256::piece(std::string_view bytes) {
  update(std::to_string(bytes.size()));
  update(":");
  update(bytes);
}

std::string Sha256::hex() {
  unsigned char out[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_DigestFinal_ex(ctx_->md, out, &n) != 1) throw std::runtime_error("SHA-256 final failed");
  static const char digits[] = "0123456789abcdef";
  std::string h;
  for (unsigned int i = 0; i < n; ++i) h += digits[out[i] >> 4], h += digits[out[i] & 15];
  return h;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 s;
  s.update(bytes);
  return s.hex();
}

}  // namespace autumn
