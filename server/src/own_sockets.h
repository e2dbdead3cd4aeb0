// This process's own sockets as the connection guard sees them through /proc/self/fd: which are
// connections accepted on the listening port, who is at the other end, how much they received.
// (cpp-httplib does not tell its handlers which socket a request came on.)
#pragma once

#include <cstdint>
#include <string>

namespace tessera::server {

/// The inode of the socket behind `fd` ("socket:[1234]"), 0 if it is not a socket.
uint64_t socket_inode(int fd);
/// "address:port" of the other end of `fd`, exactly as httplib writes remote_addr and remote_port,
/// if `fd` is a connection accepted on `listen_port`; "" otherwise (the listener, other sockets).
std::string accepted_peer(int fd, int listen_port);
/// Bytes the kernel has received on the TCP socket `fd` (TCP_INFO); false if it cannot tell.
bool bytes_received(int fd, uint64_t& bytes);
/// Shuts down (`how`: SHUT_RD, SHUT_RDWR) the connection from `peer` accepted on `listen_port`, if
/// it is open; false if there is none. Costs a walk over this process's descriptors.
bool shut_down_connection(int listen_port, const std::string& peer, int how);

}  // namespace tessera::server
