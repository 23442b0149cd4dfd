#!/usr/bin/env python3
"""A Foxglove WebSocket client that subscribes to every channel and then does not read (crane_web's
bad-input test, tests/web/foxglove_client.js abuse).

Its socket's receive buffer is fixed small (SO_RCVBUF before connecting: no autotuning), so the
bytes the kernel takes for it are bounded and the server's queue for it must fill and drop within
seconds, whatever the machine's TCP settings; crane_web then closes it (--close-stalled). The few
frames it writes and reads (the handshake, serverInfo, advertise, one subscribe, and at the end
what the server sent) are RFC 6455 by hand: a test stub, not a client library.

    stalled_client.py HOST PORT SECONDS

prints the number of channels subscribed, then stalls until a line arrives on its standard input
(or SECONDS pass); then reads what the server had sent, for at most 10 s, and prints one JSON line:
{"close_code": N or null, "close_reason": "...", "eof": bool, "data_frames": N}, a close frame's
code and reason if one came, whether the server ended the TCP connection, and the data frames
before that.
"""
import base64
import json
import os
import select
import socket
import struct
import sys
import time


def read_exact(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("stalled_client: the server ended the connection")
        data += chunk
    return data


def read_frame(sock):
    first, second = read_exact(sock, 2)
    length = second & 0x7F
    if length == 126:
        length = struct.unpack(">H", read_exact(sock, 2))[0]
    elif length == 127:
        length = struct.unpack(">Q", read_exact(sock, 8))[0]
    return first & 0x0F, read_exact(sock, length)


def send_text(sock, text, opcode=0x1):
    payload = text if isinstance(text, bytes) else text.encode()
    mask = os.urandom(4)
    header = bytes([0x80 | opcode])
    if len(payload) < 126:
        header += bytes([0x80 | len(payload)])
    else:
        header += bytes([0x80 | 126]) + struct.pack(">H", len(payload))
    sock.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))


def main():
    host, port, seconds = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 16 * 1024)
    sock.connect((host, port))
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall((f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                  f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n"
                  "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n").encode())
    response = b""
    while b"\r\n\r\n" not in response:
        response += read_exact(sock, 1)
    if b" 101 " not in response.split(b"\r\n")[0]:
        raise SystemExit(f"stalled_client: handshake refused: {response.splitlines()[0]!r}")
    channels = []
    while not channels:
        opcode, payload = read_frame(sock)
        if opcode == 1:
            message = json.loads(payload)
            if message.get("op") == "advertise":
                channels = [c["id"] for c in message["channels"]]
    send_text(sock, json.dumps({"op": "subscribe",
                                "subscriptions": [{"id": i, "channelId": c} for i, c in enumerate(channels)]}))
    print(len(channels), flush=True)
    select.select([sys.stdin], [], [], seconds)  # reads nothing from the server meanwhile
    print(json.dumps(read_to_the_end(sock, 10.0)), flush=True)
    sock.close()
    return 0


def read_to_the_end(sock, timeout):
    """Frames until a close frame, the end of the connection or `timeout` [s]."""
    result = {"close_code": None, "close_reason": "", "eof": False, "data_frames": 0}
    sock.settimeout(timeout)
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            opcode, payload = read_frame(sock)
            if opcode == 8:
                if len(payload) >= 2:
                    result["close_code"] = struct.unpack(">H", payload[:2])[0]
                    result["close_reason"] = payload[2:].decode(errors="replace")
                send_text(sock, payload[:2], opcode=0x8)  # the closing handshake's answer
                break
            result["data_frames"] += 1
        # After a close frame the server ends the connection (or after the close handshake's timeout).
        while time.monotonic() < deadline and sock.recv(65536):
            pass
        result["eof"] = time.monotonic() < deadline
    except ConnectionError:
        result["eof"] = True
    except socket.timeout:
        pass
    return result


if __name__ == "__main__":
    sys.exit(main())
