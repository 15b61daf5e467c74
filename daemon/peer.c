/* peer.c — how a client's address is named for the logs, the per-address
 * connection budgets and the login throttle, the same for the protocol's
 * listeners and the HTTP endpoint: an IPv4 address as it is, an IPv6
 * address by its /64 (one host usually holds a whole /64). */
#include "mcd.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>

void peer_name(const struct sockaddr *sa, char out[SRV_MAX_PEER])
{
    snprintf(out, SRV_MAX_PEER, "?");
    if (sa->sa_family == AF_INET) {
        inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, out, SRV_MAX_PEER);
    } else if (sa->sa_family == AF_INET6) {
        struct in6_addr a = ((const struct sockaddr_in6 *)sa)->sin6_addr;
        if (IN6_IS_ADDR_V4MAPPED(&a)) {
            inet_ntop(AF_INET, &a.s6_addr[12], out, SRV_MAX_PEER);
            return;
        }
        memset(&a.s6_addr[8], 0, 8);
        char ip[INET6_ADDRSTRLEN];
        inet_ntop(AF_INET6, &a, ip, sizeof ip);
        snprintf(out, SRV_MAX_PEER, "%s/64", ip);
    }
}
