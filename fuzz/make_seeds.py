#!/usr/bin/python3
"""Writes the seed corpora of fuzz/corpus/ (run from anywhere; needs Debian's python3-can).

msgpack_frame: datagrams made by python-can's own udp_multicast pack_message (the wire format the
  transport must accept), including an extended id, a SYNC, a remote and an error frame.
sdo:           SDO frames of the digests' test vectors (akd-canopen-part1-communication.md §18,
               stoeber-sd6-canopen.md §6.4 and §9 D-1..D-5) and segmented-transfer frames.
can_engines:   frame records (format in fuzz_can_engines.cpp) for each persona: NMT, SYNC, SDO,
               heartbeat, guarding RTR, EMCY, PDO.
eds:           copies of tests/config/devices/akd-canopen.eds and of the EDS test corpus
               tests/config/eds/*.eds (number forms, data types, CompactSubObj, a file in the wild).
config:        a copy of config/demo.yaml.
"""
import pathlib
import shutil

from can import Message
from can.interfaces.udp_multicast.utils import pack_message

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = HERE / "corpus"


def write(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(bytes(data))


def msgpack_seeds():
    msgs = {
        "tpdo": Message(timestamp=1700000000.125, arbitration_id=0x181, is_extended_id=False, data=bytes(range(1, 9))),
        "extended": Message(timestamp=0.0, arbitration_id=0x1ABCDE0, is_extended_id=True, data=b"\xde\xad"),
        "sync": Message(timestamp=3.0, arbitration_id=0x80, is_extended_id=False, data=b""),
        "rtr": Message(timestamp=12.5, arbitration_id=0x701, is_extended_id=False, is_remote_frame=True, dlc=1),
        "error": Message(timestamp=4.0, arbitration_id=0x40, is_extended_id=False, is_error_frame=True, data=bytes(8)),
        "sdo": Message(timestamp=5.0, arbitration_id=0x601, is_extended_id=False, data=bytes.fromhex("4000100000000000")),
    }
    for name, m in msgs.items():
        write("msgpack_frame", name, pack_message(m))


SDO = {
    # akd-canopen-part1-communication.md §18, vectors 9-28
    "akd09_read_1000": "40 00 10 00 00 00 00 00",
    "akd10_resp_1000": "43 00 10 00 92 01 02 00",
    "akd13_download_ok": "60 10 10 01 00 00 00 00",
    "akd16_abort": "80 22 22 00 00 00 02 06",
    "akd21_heartbeat": "2B 17 10 00 64 00 00 00",
    "akd24_life_factor": "2F 0D 10 00 03 00 00 00",
    # stoeber-sd6-canopen.md §9 D-1, D-3 and §6.4 (42h: size not indicated)
    "sd6_d1_resp_42": "42 00 10 00 92 01 02 00",
    "sd6_d3_save": "23 10 10 01 73 61 76 65",
    "sd6_upload_segment_req": "60 00 00 00 00 00 00 00",
    # segmented transfers [CiA 301 §7.2.4.3]: initiate with size, segments with n and c
    "upload_initiate_resp": "41 08 10 00 0C 00 00 00",
    "upload_segment_resp": "00 64 72 69 76 65 67 61",
    "upload_segment_last": "1B 74 65 2D 66 00 00 00",
    "download_initiate": "21 00 20 00 0C 00 00 00",
    "download_segment_resp": "30 00 00 00 00 00 00 00",
    "block": "C0 00 10 00 00 00 00 00",
}


def sdo_seeds():
    for name, hexbytes in SDO.items():
        write("sdo", name, bytes.fromhex(hexbytes))


def record(cob, data=b"", step=1, remote=False, dlc=None):
    """One frame record of fuzz_can_engines.cpp."""
    n = len(data) if dlc is None else dlc
    hi = ((cob >> 8) & 0x3F) | (0x40 if remote else 0)
    return bytes([cob & 0xFF, hi, (step << 4) | n]) + (b"" if remote else data)


def engines_seeds():
    boot = record(0x000, bytes([0x01, 0x01]), step=4) + record(0x080, step=4)
    sdo = (record(0x601, bytes.fromhex("4000100000000000"), step=2)
           + record(0x581, bytes.fromhex("4300100092010200"), step=2)
           + record(0x581, bytes.fromhex("8022220000000206"), step=7))
    err = (record(0x701, bytes([0x05]), step=4) + record(0x702, remote=True, dlc=1, step=7)
           + record(0x702, bytes([0x85]), step=7) + record(0x081, bytes.fromhex("00751001020000"), step=3)
           + record(0x081, bytes.fromhex("0000000000000000"), step=3))
    pdo = record(0x181, bytes([0x37, 0x06]), step=4) + record(0x201, bytes([0x0F, 0x00]), step=4)
    quiet = record(0x7FF, step=11) + record(0x000, bytes([0x81, 0x01]), step=9) + record(0x080, step=13)
    for persona in range(4):
        write("can_engines", f"p{persona}_boot_sdo", bytes([persona]) + boot + sdo + quiet)
        write("can_engines", f"p{persona}_errors_pdo", bytes([persona]) + boot + err + pdo + quiet)


def copies():
    d = CORPUS / "eds"
    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "tests/config/devices/akd-canopen.eds", d / "akd-canopen.eds")
    for eds in sorted((ROOT / "tests/config/eds").glob("*.eds")):
        shutil.copy(eds, d / eds.name)
    d = CORPUS / "config"
    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "config/demo.yaml", d / "demo.yaml")


if __name__ == "__main__":
    msgpack_seeds()
    sdo_seeds()
    engines_seeds()
    copies()
