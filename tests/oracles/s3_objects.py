"""An independent S3 client for the object storage tests: boto3 (PyPI, installed by
`make deps` into .venv), talking to the local moto server the test started.

Usage: .venv/bin/python3 tests/oracles/s3_objects.py ENDPOINT BUCKET COMMAND [ARGS]
  mkbucket              create BUCKET
  upload KEY FILE       put FILE's bytes as KEY
  show KEY...           one JSON line per key: head_object's ContentType and
                        ContentEncoding, and get_object's body as hex (null when absent)
  keys [PREFIX]         every key under PREFIX, one per line

Credentials are fixed ("test"/"test"): moto accepts any. An https:// endpoint's
certificate is not checked (moto makes a self-signed one).
"""

import json
import sys

import boto3
from botocore.config import Config
from botocore.exceptions import ClientError


def main():
    endpoint, bucket, command, *args = sys.argv[1:]
    s3 = boto3.client(
        "s3",
        endpoint_url=endpoint,
        aws_access_key_id="test",
        aws_secret_access_key="test",
        region_name="us-east-1",
        config=Config(s3={"addressing_style": "path"}, retries={"max_attempts": 1}),
        # moto's https:// is a self-signed certificate made at start.
        verify=not endpoint.startswith("https://"),
    )
    if command == "mkbucket":
        s3.create_bucket(Bucket=bucket)
    elif command == "upload":
        key, path = args
        with open(path, "rb") as f:
            s3.put_object(Bucket=bucket, Key=key, Body=f.read())
    elif command == "show":
        for key in args:
            try:
                head = s3.head_object(Bucket=bucket, Key=key)
            except ClientError as e:
                if e.response["Error"]["Code"] in ("404", "NoSuchKey"):
                    print(json.dumps({"key": key, "body": None}))
                    continue
                raise
            body = s3.get_object(Bucket=bucket, Key=key)["Body"].read()
            print(
                json.dumps(
                    {
                        "key": key,
                        "content_type": head.get("ContentType"),
                        "content_encoding": head.get("ContentEncoding"),
                        "body": body.hex(),
                    }
                )
            )
    elif command == "keys":
        prefix = args[0] if args else ""
        pages = s3.get_paginator("list_objects_v2").paginate(Bucket=bucket, Prefix=prefix)
        for page in pages:
            for item in page.get("Contents", []):
                print(item["Key"])
    else:
        sys.exit(f"unknown command {command}")


if __name__ == "__main__":
    main()
