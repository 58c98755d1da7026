"""Connecting to a running scheduler, in the clear or over TLS with certificates.

A Dask scheduler runs whatever pickled code a client that reaches its port sends it, on every
worker: an open, unencrypted farm port is a way into every render node. Over TLS
(``tls://HOST:PORT``) every connection (client, scheduler, workers) is encrypted, and each end
must show a certificate signed by the farm's certificate authority: a client without one is
refused. whitted takes Dask's own security settings, from its configuration or environment
(``distributed.comm.tls.ca-file``, ``.client.cert``, ``.client.key``,
``distributed.comm.require-encryption``; e.g. ``DASK_DISTRIBUTED__COMM__TLS__CA_FILE``), the
same that ``dask worker --tls-ca-file ...`` and a notebook's ``Client`` use
(:class:`distributed.security.Security`). docs/farm.md says how to set up a farm with TLS.
"""

from __future__ import annotations

import ssl

from ._dask import Client
from .errors import ClusterLost, FarmError

#: the environment variables of Dask's client TLS settings (for the one-line messages)
TLS_ENVIRONMENT = ("DASK_DISTRIBUTED__COMM__TLS__CA_FILE, "
                   "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT and "
                   "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY")


def client_security(address: str):
    """Dask's :class:`~distributed.security.Security` from its configuration, checked
    against ``address``: a ``tls://`` scheduler needs this client's certificate, key and the
    farm's certificate authority; a configuration that requires encryption takes no
    ``tcp://``. :class:`FarmError` (one line) otherwise."""
    from distributed.security import Security

    try:
        security = Security()
    except (OSError, ValueError, ssl.SSLError) as exc:
        raise FarmError(f"Dask's TLS settings cannot be used: {exc}") from None
    tls = address.startswith("tls://")
    if tls and not (security.tls_ca_file and security.tls_client_cert):
        raise FarmError(f"--scheduler {address}: a TLS scheduler needs this client's "
                        f"certificate: set {TLS_ENVIRONMENT} (Dask's distributed.comm.tls "
                        "settings; docs/farm.md)")
    if not tls and security.require_encryption:
        raise FarmError(f"--scheduler {address}: Dask's settings require encryption "
                        "(distributed.comm.require-encryption): use tls://HOST:PORT")
    return security


def connect(address: str, timeout: float) -> Client:
    """A client of the scheduler at ``address`` with Dask's security settings; one line
    (:class:`ClusterLost`) when the scheduler cannot be reached or refuses this client."""
    security = client_security(address)
    try:
        return Client(address, timeout=f"{timeout:g}s", security=security)
    except (ssl.SSLError, TypeError) as exc:  # a certificate file that is not one
        raise FarmError(f"--scheduler {address}: the TLS settings cannot be used "
                        f"({type(exc).__name__}: {str(exc).splitlines()[0][:200]})") from None
    except OSError as exc:
        if getattr(exc, "filename", None):  # a certificate or key file it cannot read
            raise FarmError(f"{exc.filename}: cannot read ({exc.strerror or exc}; a TLS "
                            "setting of Dask's)") from None
        raise _refused(address, exc, timeout) from None
    except (TimeoutError, ValueError, AssertionError) as exc:
        raise _refused(address, exc, timeout) from None


def _refused(address: str, exc: BaseException, timeout: float) -> ClusterLost:
    """The one line for a scheduler that did not take this client (never Dask's text of the
    connection)."""
    if address.startswith("tls://") and "SSL" in str(exc):
        return ClusterLost(f"--scheduler {address}: the scheduler refused this client's TLS "
                           "connection (its certificate must be signed by the farm's "
                           "certificate authority; docs/farm.md)")
    if isinstance(exc, TimeoutError | AssertionError) or "Timed out" in str(exc):
        hint = (" (a scheduler that takes only TLS needs tls:// and a certificate)"
                if address.startswith("tcp://") else "")
        return ClusterLost(f"--scheduler {address}: no answer from the scheduler in "
                           f"{timeout:g} s{hint}")
    return ClusterLost(f"--scheduler {address}: cannot reach the scheduler")
