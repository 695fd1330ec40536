#include "storage/sha256.h"

#include <openssl/evp.h>

#include "util/error.h"

namespace parapm::service {

void Sha256::Free::operator()(evp_md_ctx_st* ctx) const { EVP_MD_CTX_free(ctx); }

Sha256::Sha256() : ctx_(EVP_MD_CTX_new()) {
  if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1)
    throw_internal("sha256: OpenSSL could not start a SHA-256 digest");
}

Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(std::string_view bytes) {
  if (!ctx_ || !hex_.empty()) throw_internal("sha256: update() after hex() or after a move");
  if (bytes.empty()) return;
  if (EVP_DigestUpdate(ctx_.get(), bytes.data(), bytes.size()) != 1)
    throw_internal("sha256: OpenSSL digest update failed");
}

std::string Sha256::hex() {
  if (!hex_.empty()) return hex_;
  if (!ctx_) throw_internal("sha256: hex() after a move");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(ctx_.get(), digest, &length) != 1 || length != 32)
    throw_internal("sha256: OpenSSL digest final failed");
  static constexpr char kHex[] = "0123456789abcdef";
  hex_.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex_.push_back(kHex[digest[i] >> 4]);
    hex_.push_back(kHex[digest[i] & 0xf]);
  }
  return hex_;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 hash;
  hash.update(bytes);
  return hash.hex();
}

bool is_sha256_hex(std::string_view text) {
  if (text.size() != 64) return false;
  for (char c : text)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace parapm::service
