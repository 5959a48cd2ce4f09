"""moto's S3 server (PyPI, installed by `make deps` into .venv) for Google Cloud Storage's
XML API, which `object_store`'s Google client speaks and which is S3's for what the tile
store does (PUT, GET, DELETE, list-type=2 listings). One shim: the client configured for a
test server (`disable_oauth`) sends `Authorization: Bearer ` with no token on some
requests, which moto would parse as an AWS signature and fail on, and none on others,
which moto treats as anonymous (403 on reading a private bucket). Both get an S3
credential scope that moto reads but, as always, does not verify. Everything else is
moto's.

Usage: .venv/bin/python3 tests/oracles/moto_for_gcs.py
Prints "Running on http://127.0.0.1:PORT" on stderr once it listens (a port the system
chose), then serves until killed.
"""

import sys

from moto.moto_server.werkzeug_app import DomainDispatcherApplication, create_backend_app
from werkzeug.serving import make_server

app = DomainDispatcherApplication(create_backend_app)


SCOPE = (
    "AWS4-HMAC-SHA256 Credential=test/20260101/us-east-1/s3/aws4_request, "
    "SignedHeaders=host, Signature=0"
)


def as_s3(environ, start_response):
    if environ.get("HTTP_AUTHORIZATION", "Bearer").startswith("Bearer"):
        environ["HTTP_AUTHORIZATION"] = SCOPE
    return app(environ, start_response)


server = make_server("127.0.0.1", 0, as_s3, threaded=True)
print(f"Running on http://127.0.0.1:{server.server_port}", file=sys.stderr, flush=True)
server.serve_forever()
