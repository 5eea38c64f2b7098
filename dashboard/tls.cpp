#include "dashboard/tls.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <arpa/inet.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509v3.h>

namespace robodamp::dashboard {

namespace {

template <typename T, void (*Free)(T*)>
struct Freer {
  void operator()(T* p) const { Free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Freer<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Freer<X509, X509_free>>;
using Ext = std::unique_ptr<X509_EXTENSION, Freer<X509_EXTENSION, X509_EXTENSION_free>>;

bool is_ip(const std::string& host) {
  unsigned char buf[16];
  return inet_pton(AF_INET, host.c_str(), buf) == 1 || inet_pton(AF_INET6, host.c_str(), buf) == 1;
}

void add_extension(X509* cert, int nid, const std::string& value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, cert, cert, nullptr, nullptr, 0);
  const Ext ext(X509V3_EXT_conf_nid(nullptr, &ctx, nid, value.c_str()));
  if (!ext || X509_add_ext(cert, ext.get(), -1) != 1) throw std::runtime_error("cannot add the extension " + value);
}

Cert self_signed(EVP_PKEY* key, const SelfSignedRequest& r) {
  Cert cert(X509_new());
  if (!cert) throw std::runtime_error("cannot make a certificate");
  X509_set_version(cert.get(), 2);  // v3
  unsigned char serial[16];
  RAND_bytes(serial, sizeof serial);
  serial[0] &= 0x7f;  // positive
  BIGNUM* bn = BN_bin2bn(serial, sizeof serial, nullptr);
  BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(cert.get()));
  BN_free(bn);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), 0);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), static_cast<long>(r.days) * 86400L);
  X509_set_pubkey(cert.get(), key);
  X509_NAME* name = X509_get_subject_name(cert.get());
  const std::string cn = "robodamp dashboard " + r.hosts.front();
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(cn.c_str()), -1, -1, 0);
  X509_set_issuer_name(cert.get(), name);
  std::string san;
  for (const auto& h : r.hosts) {
    if (!san.empty()) san += ',';
    san += is_ip(h) ? "IP:" : "DNS:";
    san += h;
  }
  add_extension(cert.get(), NID_subject_alt_name, san);
  add_extension(cert.get(), NID_basic_constraints, "critical,CA:FALSE");
  add_extension(cert.get(), NID_key_usage, "critical,digitalSignature");
  add_extension(cert.get(), NID_ext_key_usage, "serverAuth");
  if (X509_sign(cert.get(), key, EVP_sha256()) == 0) throw std::runtime_error("cannot sign the certificate");
  return cert;
}

// Opens for writing with `mode`, refusing an existing file unless overwrite.
std::FILE* open_new(const std::string& path, mode_t mode, bool overwrite) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (overwrite ? O_TRUNC : O_EXCL), mode);
  if (fd < 0)
    throw std::runtime_error(path + (errno == EEXIST ? ": exists (--overwrite replaces it)" : ": cannot be written"));
  if (overwrite) ::fchmod(fd, mode);
  std::FILE* f = ::fdopen(fd, "w");
  if (f == nullptr) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot be written");
  }
  return f;
}

}  // namespace

void write_self_signed(const std::string& certificate_path, const std::string& key_path, const SelfSignedRequest& r) {
  if (r.hosts.empty()) throw std::runtime_error("a certificate needs at least one host name or address");
  if (r.days < 1 || r.days > 3650)
    throw std::runtime_error("days = " + std::to_string(r.days) + " is out of range: allowed 1 <= value <= 3650 days");
  const Key key(EVP_EC_gen("P-256"));
  if (!key) throw std::runtime_error("cannot make an EC P-256 key");
  const Cert cert = self_signed(key.get(), r);
  for (const auto& p : {certificate_path, key_path})
    if (!r.overwrite && std::filesystem::exists(p)) throw std::runtime_error(p + ": exists (--overwrite replaces it)");
  std::FILE* k = open_new(key_path, 0600, r.overwrite);
  const bool key_ok = PEM_write_PrivateKey(k, key.get(), nullptr, nullptr, 0, nullptr, nullptr) == 1;
  const bool key_closed = std::fclose(k) == 0;
  if (!key_ok || !key_closed) throw std::runtime_error(key_path + ": cannot be written");
  std::FILE* c = open_new(certificate_path, 0644, r.overwrite);
  const bool cert_ok = PEM_write_X509(c, cert.get()) == 1;
  const bool cert_closed = std::fclose(c) == 0;
  if (!cert_ok || !cert_closed) throw std::runtime_error(certificate_path + ": cannot be written");
}

bool is_loopback_address(const std::string& address) {
  if (address == "localhost" || address == "::1") return true;
  in_addr a{};
  return inet_pton(AF_INET, address.c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

std::string plain_http_refusal(const config::DashboardConfig& cfg, bool plain_http_allowed) {
  if (cfg.tls() || plain_http_allowed || is_loopback_address(cfg.listen_address)) return {};
  return "plain HTTP on " + cfg.listen_address +
         " is refused: passwords and session tokens would cross the network readable. Give "
         "dashboard.tls_certificate and dashboard.tls_private_key (robodamp dashboard-cert makes a self-signed "
         "pair), listen on 127.0.0.1 behind a TLS proxy or an SSH tunnel, or pass --insecure-http to accept that "
         "cost";
}

}  // namespace robodamp::dashboard
