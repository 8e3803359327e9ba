"""TLS, mutual TLS and bearer tokens from Python against real servers
started with the throw-away certificates of tests/certs/."""
import pathlib

import pytest

import kinplan

CERTS = pathlib.Path(__file__).resolve().parents[3] / "tests" / "certs"


def tls_args(mutual=False):
    args = ["--tls-cert", str(CERTS / "server.pem"), "--tls-key", str(CERTS / "server.key")]
    if mutual:
        args += ["--tls-client-ca", str(CERTS / "ca.pem")]
    return args


def test_tls_with_the_ca_answers_and_without_it_fails():
    with kinplan.LocalServer(args=tls_args()) as server:
        server_address = server.address
        with kinplan.Client(server_address, timeout=5, tls_ca=str(CERTS / "ca.pem")) as c:
            assert c.ping() > 0
        with kinplan.Client(server_address, timeout=2) as plain:
            with pytest.raises(kinplan.KinplanError):
                plain.ping()


def test_mutual_tls_needs_the_client_certificate():
    with kinplan.LocalServer(args=tls_args(mutual=True)) as server:
        ca = (CERTS / "ca.pem").read_bytes()
        with kinplan.Client(server.address, timeout=5, tls_ca=ca, tls_cert=str(CERTS / "client.pem"),
                            tls_key=str(CERTS / "client.key")) as c:
            assert c.list_robots()
        with kinplan.Client(server.address, timeout=2, tls_ca=ca) as no_cert:
            with pytest.raises(kinplan.KinplanError):
                no_cert.ping()


def test_a_token_is_required_and_sent_on_every_kind_of_call():
    with kinplan.LocalServer(args=["--auth-tokens", "tok-1,tok-2"]) as server:
        with kinplan.Client(server.address, timeout=5) as anonymous:
            with pytest.raises(kinplan.KinplanError) as err:
                anonymous.ping()
            assert err.value.code_name == "UNAUTHENTICATED"
        with kinplan.Client(server.address, timeout=5, token="tok-2") as c:
            ur5 = c.robot("ur5")
            assert ur5.fk([0.0] * 6).shape == (4, 4)  # unary
            steps = list(c.explore(scene=kinplan.scenes.s0_open_cell(c), resolution=0.2, pixel_stride=8,
                                   max_iterations=1))  # server streaming
            assert isinstance(steps[-1], kinplan.ExploreSummary)
        with kinplan.Client(server.address, timeout=5, token="tok-3") as wrong:
            with pytest.raises(kinplan.KinplanError, match="UNAUTHENTICATED"):
                wrong.ping()


def test_client_certificates_without_tls_are_refused_locally():
    with pytest.raises(kinplan.InvalidArgument, match="tls_ca"):
        kinplan.Client("127.0.0.1:1", tls_cert=b"x", tls_key=b"y")
