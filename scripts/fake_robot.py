#!/usr/bin/env python3
"""A fake robot controller for `kincal capture --robot-listen` (docs/LAB.md).

Visits the poses of a CSV file (kincal plan's POSES.csv, or any file with a
`pose` column and one column per joint, e.g. observations.csv) and speaks the
step-and-shoot line protocol: HELLO with the joint names, then for every
pose SETTLED <pose> <q...>, waiting for kincal's DONE before the next one,
and BYE at the end. Standard library only.

  python3 scripts/fake_robot.py --port 30010 --poses poses.csv [--move-s 0.2]
"""
import argparse
import csv
import socket
import sys
import time

NOT_JOINTS = {"pose", "x", "y", "z", "t", "fixed_point", "temp_c"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--poses", required=True, help="CSV: pose + joint columns")
    ap.add_argument("--name", default="fake-robot")
    ap.add_argument("--move-s", type=float, default=0.0,
                    help="pretend each move takes this long")
    ap.add_argument("--drop-after", type=int, default=-1,
                    help="close the link without BYE after N poses (a fault)")
    ap.add_argument("--connect-timeout", type=float, default=30.0)
    args = ap.parse_args()

    with open(args.poses, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header, rows = rows[0], rows[1:]
    joints = [c for c in header if c not in NOT_JOINTS]
    idx = [header.index(c) for c in joints]
    pose_col = header.index("pose") if "pose" in header else None

    deadline = time.time() + args.connect_timeout
    while True:
        try:
            sock = socket.create_connection((args.host, args.port), timeout=60)
            break
        except OSError:
            if time.time() > deadline:
                sys.exit("fake_robot: cannot connect to %s:%d" %
                         (args.host, args.port))
            time.sleep(0.1)
    reader = sock.makefile("r", encoding="ascii", newline="\n")

    def send(line):
        sock.sendall((line + "\n").encode("ascii"))

    def expect(prefix):
        reply = reader.readline().strip()
        if not reply.startswith(prefix):
            sys.exit("fake_robot: kincal answered '%s'" % reply)
        return reply

    send("HELLO %s %s" % (args.name, " ".join(joints)))
    expect("OK")
    for n, row in enumerate(rows):
        if n == args.drop_after:
            sock.close()
            print("fake_robot: dropped the link after %d poses" % n)
            return
        time.sleep(args.move_s)
        pose = row[pose_col] if pose_col is not None else str(n)
        if not pose.lstrip("-").isdigit():
            pose = str(n)
        send("SETTLED %s %s" % (pose, " ".join(row[i] for i in idx)))
        expect("DONE")
    send("BYE")
    sock.close()
    print("fake_robot: visited %d poses" % len(rows))


if __name__ == "__main__":
    main()
