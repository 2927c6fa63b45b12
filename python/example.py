#!/usr/bin/env python3
"""Example robot-controller loop: follow the humanoid's pose served by hposed.

    python3 python/example.py --server 127.0.0.1:50051 --count 10   (after pip install ./python)

With a stereo source (and world_from_ground) in the daemon, both estimators' estimates arrive,
each marked with its estimator; --estimator picks one.
"""

import argparse
import sys

from hpose_client import PoseClient, PoseClientError, best_pose
from hpose_client.client import describe


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--count", type=int, default=10, help="estimates to read (0 = forever)")
    parser.add_argument("--estimator", choices=["depth", "stereo"], default=None,
                        help="only this estimator's estimates (default: all)")
    parser.add_argument("--tls-ca", help="PEM CA of the daemon's certificate: connect with TLS")
    parser.add_argument("--tls-cert", help="PEM client certificate (mutual TLS, with --tls-key)")
    parser.add_argument("--tls-key", help="PEM private key of --tls-cert")
    parser.add_argument("--token-file", help="file whose first line is the bearer token")
    args = parser.parse_args()

    with PoseClient(args.server, tls_ca=args.tls_ca, tls_cert=args.tls_cert,
                    tls_key=args.tls_key, token_file=args.token_file) as client:
        try:
            client.wait_ready(timeout=10)
            status = client.status()
            print("daemon %s, source %s (%s)" % (status.version, status.source.description,
                                                 status.source.kind))
            for t in client.templates():
                print("template %s: %d voxels, %.0f mm tall" % (t.name, t.voxels, t.height * 1000))
            seen = 0
            estimators = [args.estimator] if args.estimator else []
            for estimate in client.stream(max_estimates=args.count, estimators=estimators):
                print(describe(estimate))
                pose = best_pose(estimate)
                if pose is not None and not estimate.stale:
                    pass  # A controller would act on (x, y, theta) here.
                seen += 1
            print("received %d estimate(s)" % seen)
        except PoseClientError as e:
            print("hposed: %s" % e, file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
