#include "viscera/console/tls_context.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <boost/asio/buffer.hpp>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include "viscera/common/input_error.hpp"
#include "viscera/common/json_input.hpp"

namespace viscera::console {

std::shared_ptr<boost::asio::ssl::context> make_tls_context(const std::string& certificate_file, const std::string& key_file) {
  namespace ssl = boost::asio::ssl;
  // Read here (a regular file, bounded), never handed to OpenSSL by name: a FIFO or /dev/zero
  // would keep it reading.
  constexpr std::size_t kMaxPemBytes = 1u << 20;
  const std::string chain = common::read_text_file(certificate_file, kMaxPemBytes);
  const std::string key = common::read_text_file(key_file, kMaxPemBytes);
  auto ctx = std::make_shared<ssl::context>(ssl::context::tls_server);
  ctx->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 | ssl::context::single_dh_use);
  SSL_CTX_set_min_proto_version(ctx->native_handle(), TLS1_2_VERSION);
  boost::system::error_code ec;
  ctx->use_certificate_chain(boost::asio::buffer(chain), ec);
  if (ec) throw common::InputError(certificate_file, 0, "certificate", "not a PEM certificate chain (" + ec.message() + ")");
  ctx->use_private_key(boost::asio::buffer(key), ssl::context::pem, ec);
  if (ec)
    throw common::InputError(key_file, 0, "private key",
                             "not a PEM private key of the certificate in " + common::printable(certificate_file, 200) + " (" + ec.message() + ")");
  if (SSL_CTX_check_private_key(ctx->native_handle()) != 1)
    throw common::InputError(key_file, 0, "private key", "is not the key of the certificate in " + common::printable(certificate_file, 200));
  const X509* cert = SSL_CTX_get0_certificate(ctx->native_handle());
  if (X509_cmp_current_time(X509_get0_notBefore(cert)) > 0)
    throw common::InputError(certificate_file, 0, "certificate", "is not valid yet (its notBefore lies in the future: check the clock)");
  if (X509_cmp_current_time(X509_get0_notAfter(cert)) < 0) throw common::InputError(certificate_file, 0, "certificate", "has expired (notAfter)");
  return ctx;
}

}  // namespace viscera::console
