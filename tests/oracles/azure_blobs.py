"""An independent Azure Blob Storage client for the object storage tests:
azure-storage-blob (PyPI, installed by `make deps` into .venv), talking to the local
Azurite server the test started, with Azurite's well-known development account.

Usage: .venv/bin/python3 tests/oracles/azure_blobs.py ENDPOINT CONTAINER COMMAND [ARGS]
  mkcontainer           create CONTAINER
  dump PREFIX           one JSON line per blob under PREFIX, in name order: its name,
                        content type and encoding, and body as hex

ENDPOINT is Azurite's blob endpoint, http://127.0.0.1:PORT.
"""

import json
import sys

from azure.storage.blob import BlobServiceClient

ACCOUNT = "devstoreaccount1"
# Azurite's published development key (not a secret).
KEY = "Eby8vdM02xNOcqFlqUwJPLlmEtlCDXJ1OUzFT50uSRZ6IFsuFq2UVErCz4I6tq/K1SZFPTOtr/KBHBeksoGMGw=="


def main():
    endpoint, container, command, *args = sys.argv[1:]
    connection = (
        f"DefaultEndpointsProtocol=http;AccountName={ACCOUNT};AccountKey={KEY};"
        f"BlobEndpoint={endpoint}/{ACCOUNT};"
    )
    service = BlobServiceClient.from_connection_string(connection)
    client = service.get_container_client(container)
    if command == "mkcontainer":
        client.create_container()
    elif command == "dump":
        (prefix,) = args
        for blob in client.list_blobs(name_starts_with=prefix):
            settings = blob.content_settings
            # The stored bytes, as CesiumJS gets them (not decoded by the client).
            body = client.download_blob(blob.name, decompress=False).readall()
            print(json.dumps({
                "key": blob.name,
                "content_type": settings.content_type,
                "content_encoding": settings.content_encoding,
                "body": body.hex(),
            }))
    else:
        sys.exit(f"unknown command {command!r}")


if __name__ == "__main__":
    main()
