#pragma once  // SPDX-License-Identifier: Apache-2.0
// The console's TLS side: the certificate chain and private key it serves HTTPS and WSS with.
#include <memory>
#include <string>

#include <boost/asio/ssl/context.hpp>

namespace viscera::console {

/// A TLS server context (TLS 1.2 or newer) from a PEM certificate chain (the console's certificate
/// first, then any intermediates) and its PEM private key, each a regular file of at most 1 MiB.
/// Throws common::InputError naming the file and OpenSSL's reason: unreadable, not PEM, a key that
/// is not the certificate's, a certificate not valid yet or any more.
std::shared_ptr<boost::asio::ssl::context> make_tls_context(const std::string& certificate_file, const std::string& key_file);

}  // namespace viscera::console
