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
esi:           copies of the ESI test files tests/config/esi/*.xml (a drive, a DC drive, I/O terminals)
               and a few small malformed ones.
config:        a copy of config/demo.yaml.
ethercat_frame:   EtherCAT frames (ETG.1000.4 §5 layout): one APRD, a multi-datagram frame, a
                  VLAN-tagged frame, a cyclic LRW + FRMW frame, a frame with C bit, truncated ones.
ethercat_mailbox: SM1 mailboxes: the digest's TV-6 SDO download, TV-4 emergencies, SDO responses
                  (expedited, normal, segments, abort), SDO information replies, a mailbox error.
ethercat_sii:     SII images: a minimal one and one with every category the parser reads.
profinet_dcp:     PROFINET frames with DCP (IEC 61158-6-10 §4.3.1): Identify all / by name, an Identify
                  response with every block the decoder reads, Set name / IP / Signal, a Set
                  response, Get request and response, and malformed ones (lying lengths, odd blocks).
profinet_rt:      RT class 1 frames behind their C_SDU length and last cycle counter (mode byte 0),
                  and submodule lists for the C_SDU layout (mode byte 1).
profinet_alarm:   RTA frames: a diagnosis alarm (DATA), the RTA ACK, an AlarmAck, an ERR, a low
                  pull alarm, and malformed ones.
ethercat_sim:     operation scripts (format in fuzz_ethercat_sim.cpp): addressing and identity
                  reads, a bring-up to PRE-OP with an SDO upload through the mailbox, process data
                  to OP with LRW, a DC latch, faults.
profinet_rpc:     PNIO DCE/RPC datagrams (UDP 34964) in both drep byte orders: Connect request and
                  responses (OK with a ModuleDiffBlock, refused without blocks), record Write of
                  index 47 (the AKD digest's PNU 930 request) and Read of I&M0 with responses,
                  PrmEnd, ApplicationReady, Release, a fault, a ping, a truncated one.
profinet_blocks:  the block lists (NDR args) of those datagrams, one file each.
profinet_dcp_engines: the profinet_dcp frames as records (format in fuzz_profinet_dcp_engines.cpp),
                  one per file, and one file with them all 100 ms apart.
profinet_alarm_engines: the profinet_alarm frames as records (format in
                  fuzz_profinet_alarm_engines.cpp), one per file, and one file with them all.
profinet_rt_consumer: records of input frames (format in fuzz_profinet_rt_consumer.cpp): cycles on
                  time, repeated and old counters, silence past the data hold time and a re-arm,
                  STOP / invalid / backup / Ignore, another source, FrameID and C_SDU length.
profinet_sim_device: records for the simulated IO device (format in fuzz_profinet_sim_device.cpp):
                  the profinet_dcp frames, the profinet_rpc requests to its server port, an
                  enable by STW1, each fault, and one file with all of them.
"""
import struct
import pathlib
import shutil

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = HERE / "corpus"


def write(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(bytes(data))


def msgpack_seeds():
    # python-can only here, so the other corpora can be written without it.
    from can import Message
    from can.interfaces.udp_multicast.utils import pack_message

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
    d = CORPUS / "esi"
    d.mkdir(parents=True, exist_ok=True)
    for esi in sorted((ROOT / "tests/config/esi").glob("*.xml")):
        shutil.copy(esi, d / esi.name)
    (d / "unclosed.xml").write_text("<EtherCATInfo><Vendor><Id>#x2</Id></Vendor>\n<Descriptions>")
    (d / "alias-cycle.xml").write_text(
        "<EtherCATInfo><Vendor><Id>2</Id></Vendor><Descriptions><Devices><Device><Type ProductCode=\"1\"/>"
        "<Profile><Dictionary><DataTypes><DataType><Name>A</Name><BaseType>B</BaseType></DataType>"
        "<DataType><Name>B</Name><BaseType>A</BaseType></DataType><DataType><Name>R</Name>"
        "<SubItem><SubIdx>0</SubIdx><Name>n</Name><Type>A</Type><BitSize>8</BitSize></SubItem>"
        "<SubItem><Name>E</Name><Type>ARR</Type></SubItem></DataType><DataType><Name>ARR</Name>"
        "<BaseType>UINT</BaseType><ArrayInfo><LBound>1</LBound><Elements>3</Elements></ArrayInfo></DataType>"
        "</DataTypes><Objects><Object><Index>#x2000</Index><Name>r</Name><Type>R</Type></Object>"
        "<Object><Index>#x2001</Index><Name>a</Name><Type>A</Type><BitSize>16</BitSize></Object>"
        "</Objects></Dictionary></Profile></Device></Devices></Descriptions></EtherCATInfo>\n")
    d = CORPUS / "config"
    d.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "config/demo.yaml", d / "demo.yaml")


def ecat_frame(datagrams, vlan=False):
    """datagrams: (cmd, idx, address, data, wkc, circulating). Ethernet II + EtherCAT header."""
    body = b""
    for i, (cmd, idx, adr, data, wkc, circ) in enumerate(datagrams):
        word = len(data) | (0x4000 if circ else 0) | (0x8000 if i + 1 < len(datagrams) else 0)
        body += struct.pack("<BBIHH", cmd, idx, adr, word, 0) + data + struct.pack("<H", wkc)
    eth = b"\xff" * 6 + bytes([2, 0, 0, 0, 0, 1])
    if vlan:
        eth += bytes([0x81, 0x00, 0x00, 0x05])
    f = eth + b"\x88\xa4" + struct.pack("<H", len(body) | 0x1000) + body
    return f + bytes(max(0, 60 - len(f)))


def ethercat_frame_seeds():
    aprd = ecat_frame([(1, 5, 0x0130FFFF, bytes([0x02, 0x00]), 1, False)])
    multi = ecat_frame([(7, 0, 0, bytes([0x11]), 3, False), (5, 1, 0x01201001, bytes([2, 0]), 1, False),
                        (12, 2, 0x00010000, bytes([0x0F, 0, 0x45, 0x23, 0x27, 0]), 3, False)])
    cyclic = ecat_frame([(14, 3, 0x09101001, bytes(8), 2, False), (12, 4, 0x00010000, bytes(24), 9, False)])
    write("ethercat_frame", "aprd_al_status", aprd)
    write("ethercat_frame", "multi_datagram", multi)
    write("ethercat_frame", "vlan", ecat_frame([(7, 9, 0, bytes(2), 2, False)], vlan=True))
    write("ethercat_frame", "cyclic_frmw_lrw", cyclic)
    write("ethercat_frame", "circulating", ecat_frame([(8, 1, 0x01200000, bytes([1, 0]), 0, True)]))
    write("ethercat_frame", "truncated", multi[:40])
    write("ethercat_frame", "wrong_ethertype", aprd[:12] + b"\x08\x00" + aprd[14:])


def mbx(counter, mtype, payload):
    return struct.pack("<HHBB", len(payload), 0, 0, (counter << 4) | mtype) + payload


def coe(counter, service, body):
    return mbx(counter, 3, struct.pack("<H", service << 12) + body)


def ethercat_mailbox_seeds():
    h = bytes.fromhex
    seeds = {
        # dunker-ethercat-coe.md §13 TV-6 step 3, TV-4 8100h and A000h
        "tv6_step3": h("0A000000001300202300160110004060"),
        "tv4_emcy_8100": h("0A000000003300100081110000000000"),
        "tv4_emcy_a000": coe(1, 1, h("00A0010000000000")),
        "sdo_download_resp": coe(2, 3, h("6000160100000000")),
        "sdo_upload_expedited": coe(3, 3, h("4B121C0100160000")),
        "sdo_upload_normal": coe(4, 3, h("410810000C000000") + b"driv"),
        "sdo_upload_segment_last": coe(5, 3, h("192D663100000000")),
        "sdo_download_segment": coe(6, 2, h("01") + b"vegate-f1"),
        "sdo_abort": coe(7, 2, h("80121C0010000706")),
        "sdo_upload_ca": coe(1, 2, h("50121C0000000000")),
        "info_od_list": coe(2, 8, h("82000100") + h("0100") + h("001018104060")),
        "info_object": coe(3, 8, h("04000000") + h("406006000007") + b"Controlword"),
        "info_entry": coe(4, 8, h("06000000") + h("60600078030010007F00") + h("000000FBFF0A00") + b"Modes"),
        "info_error": coe(5, 8, h("07000000") + h("00000206")),
        "mailbox_error": mbx(1, 0, h("01000200")),
        "padded_sm1": h("0A000000001300306000160100000000") + bytes([0xFF] * 112),
    }
    for name, data in seeds.items():
        write("ethercat_mailbox", name, data)


def crc8(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def sii_image(categories, size=2048):
    """ETG.1000.6 §5.4: header words 0-3Fh with the CRC-8 in word 7, then categories."""
    head = struct.pack("<7H", 0x0C08, 0, 0, 0, 0, 0, 0)
    head += struct.pack("<H", crc8(head))
    head += struct.pack("<4I", 0x0F, 0x1A63, 1, 42) + bytes(8)
    head += struct.pack("<9H", 0, 0, 0, 0, 0x1000, 128, 0x1080, 128, 0x0004)
    head += bytes(2 * 0x3E - len(head)) + struct.pack("<HH", size // 128 - 1, 1)
    body = b""
    for ctype, data in categories:
        if len(data) % 2:
            data += b"\x00"
        body += struct.pack("<HH", ctype, len(data) // 2) + data
    img = head + body + b"\xff\xff"
    return img + b"\xff" * (size - len(img))


def ethercat_sii_seeds():
    strings = bytes([3]) + b"\x06Drives" + b"\x09TrioDrive" + b"\x0aStatusword"
    general = bytes([1, 0, 2, 2, 0, 0x0F, 0, 0, 0, 1, 0, 1]) + bytes(4) + struct.pack("<HH", 0x11, 0) + bytes(12)
    sms = (struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 1) + struct.pack("<HHBBBB", 0x1080, 128, 0x22, 0, 1, 2)
           + struct.pack("<HHBBBB", 0x1100, 6, 0x64, 0, 1, 3) + struct.pack("<HHBBBB", 0x1180, 6, 0x20, 0, 1, 4))
    txpdo = struct.pack("<HBBBBH", 0x1A00, 2, 3, 0, 0, 0) + struct.pack("<HBBBBH", 0x6041, 0, 3, 6, 16, 0) \
        + struct.pack("<HBBBBH", 0x6063, 0, 0, 4, 32, 0)
    rxpdo = struct.pack("<HBBBBH", 0x1600, 2, 2, 0, 0, 0) + struct.pack("<HBBBBH", 0x6040, 0, 0, 6, 16, 0) \
        + struct.pack("<HBBBBH", 0x60C1, 1, 0, 4, 32, 0)
    dc = struct.pack("<IIIhHhBB", 1000000, 0, 0, 0, 0x0300, 1, 0, 0) + bytes(4)
    write("ethercat_sii", "minimal", sii_image([], size=256))
    write("ethercat_sii", "full", sii_image([(10, strings), (30, general), (40, bytes([1, 2, 3])), (41, sms),
                                             (50, txpdo), (51, rxpdo), (60, dc)]))
    write("ethercat_sii", "header_only", sii_image([])[:128])


def sim_dg(cmd, adp, ado, data):
    """One datagram operation of fuzz_ethercat_sim.cpp: command, address (ADP | ADO << 16), length u8, data."""
    return bytes([cmd]) + struct.pack("<HHB", adp, ado, len(data)) + data


def ethercat_sim_seeds():
    st0, st1 = 0x1001, 0x1002
    addr = sim_dg(2, 0, 0x10, struct.pack("<H", st0)) + sim_dg(2, 0xFFFF, 0x10, struct.pack("<H", st1))
    ident = sim_dg(7, 0, 0, bytes(1)) + sim_dg(4, st0, 0, bytes(10)) + sim_dg(4, st1, 0, bytes(10))
    # SM0/SM1 of the CoE slave (ETG.1000.4 Table 59 entries), PRE-OP, an SDO upload of 1000h.
    sm0 = struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 0)
    sm1 = struct.pack("<HHBBBB", 0x1080, 128, 0x22, 0, 1, 0)
    upload = struct.pack("<HHBB", 10, 0, 0, 0x13) + struct.pack("<H", 0x2000) + bytes([0x40, 0x00, 0x10, 0]) + bytes(4)
    mbx_seq = (sim_dg(5, st0, 0x800, sm0) + sim_dg(5, st0, 0x808, sm1) + sim_dg(5, st0, 0x120, bytes([2, 0]))
               + sim_dg(5, st0, 0x1000, upload + bytes(128 - len(upload))) + b"\xf1"
               + sim_dg(4, st0, 0x80D, bytes(1)) + sim_dg(4, st0, 0x1080, bytes(128)))
    # Generic slave to OP: SM2/SM3, FMMUs, LRW.
    sm2 = struct.pack("<HHBBBB", 0x1000, 2, 0x64, 0, 1, 0)
    sm3 = struct.pack("<HHBBBB", 0x1100, 2, 0x20, 0, 1, 0)
    f0 = struct.pack("<IHBBHBBBxxx", 0x10000, 2, 0, 7, 0x1000, 0, 2, 1)
    f1 = struct.pack("<IHBBHBBBxxx", 0x10002, 2, 0, 7, 0x1100, 0, 1, 1)
    pd = (sim_dg(5, st1, 0x810, sm2) + sim_dg(5, st1, 0x818, sm3) + sim_dg(5, st1, 0x600, f0)
          + sim_dg(5, st1, 0x610, f1) + sim_dg(5, st1, 0x120, bytes([2, 0])) + sim_dg(5, st1, 0x120, bytes([4, 0]))
          + sim_dg(5, st1, 0x120, bytes([8, 0])) + sim_dg(12, 0, 1, bytes([0x11, 0x22, 0, 0])) + b"\xff\xff")
    dc = sim_dg(8, 0, 0x900, bytes(4)) + sim_dg(4, st1, 0x900, bytes(16)) + sim_dg(13, 0, 0x910, bytes(8))
    faults = addr + b"\xe0" + sim_dg(7, 0, 0, bytes(1)) + b"\xe1\xe2\xe3\xe4" + sim_dg(7, 0, 0, bytes(1)) + b"\xe5"
    write("ethercat_sim", "identity", addr + ident)
    write("ethercat_sim", "mailbox", addr + mbx_seq)
    write("ethercat_sim", "process_data", addr + pd)
    write("ethercat_sim", "dc", addr + dc)
    write("ethercat_sim", "faults", faults)


PN_DEVICE = bytes([0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56])
PN_CONTROLLER = bytes([2, 0, 0, 0, 0, 1])


def pn_frame(dst, src, frame_id, pdu, prio=None):
    """Ethernet II (optionally priority tagged) + EtherType 8892h + FrameID, padded to 60."""
    tag = b"" if prio is None else struct.pack(">HH", 0x8100, prio << 13)
    f = dst + src + tag + struct.pack(">HH", 0x8892, frame_id) + pdu
    return f + bytes(max(0, 60 - len(f)))


def dcp_block(option, sub, value):
    return struct.pack(">BBH", option, sub, len(value)) + value + (b"\0" if len(value) % 2 else b"")


def dcp(service, stype, xid, blocks, delay=0):
    body = b"".join(blocks)
    return struct.pack(">BBIHH", service, stype, xid, delay, len(body)) + body


def profinet_seeds():
    ip = bytes([192, 168, 0, 10, 255, 255, 255, 0, 192, 168, 0, 1])
    mc = bytes([1, 0x0E, 0xCF, 0, 0, 0])
    info = [dcp_block(2, 1, b"\0\0AKD"), dcp_block(2, 2, b"\0\0akd-1"), dcp_block(2, 3, bytes.fromhex("0000002A0301")),
            dcp_block(2, 4, bytes.fromhex("00000100")), dcp_block(2, 5, bytes.fromhex("000001020202")),
            dcp_block(2, 7, bytes.fromhex("00000001")), dcp_block(2, 8, bytes.fromhex("000012345678")),
            dcp_block(1, 2, b"\0\1" + ip), dcp_block(1, 1, b"\0\0" + PN_DEVICE), dcp_block(3, 61, b"\0\0\0akd1"),
            dcp_block(6, 1, bytes.fromhex("00000001"))]
    seeds = {
        "identify_all": pn_frame(mc, PN_CONTROLLER, 0xFEFE, dcp(5, 0, 1, [dcp_block(255, 255, b"")], 1)),
        "identify_name": pn_frame(mc, PN_CONTROLLER, 0xFEFE, dcp(5, 0, 2, [dcp_block(2, 2, b"akd-1")], 0x80)),
        "identify_response": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFEFF, dcp(5, 1, 1, info)),
        "set_name": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFEFD, dcp(4, 0, 3, [dcp_block(2, 2, b"\0\1akd-1")])),
        "set_ip": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFEFD, dcp(4, 0, 4, [dcp_block(1, 2, b"\0\0" + ip)])),
        "signal": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFEFD, dcp(4, 0, 5, [dcp_block(5, 3, bytes.fromhex("00000100"))])),
        "set_response": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFEFD,
                                 dcp(4, 1, 3, [dcp_block(5, 4, bytes([2, 2, 0])), dcp_block(5, 4, bytes([1, 2, 6]))])),
        "get_request": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFEFD, dcp(3, 0, 6, [bytes([2, 2, 1, 2])])),
        "get_response": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFEFD, dcp(3, 1, 6, [dcp_block(2, 2, b"\0\0akd-1")])),
        "hello_tagged": pn_frame(bytes([1, 0x0E, 0xCF, 0, 0, 1]), PN_DEVICE, 0xFEFC, dcp(6, 0, 7, info[:3]), prio=0),
    }
    bad_len = bytearray(seeds["identify_name"])
    bad_len[24] = 0x01  # DCPDataLength 010Ah: beyond the frame
    odd_ip = pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFEFF, dcp(5, 1, 1, [dcp_block(1, 2, b"\0\1" + ip[:11])]))
    seeds.update({"lying_length": bytes(bad_len), "odd_ip_block": odd_ip, "truncated": seeds["identify_response"][:30]})
    for name, data in seeds.items():
        write("profinet_dcp", name, data)
    records = {name: bytes([10]) + struct.pack(">H", len(data)) + data for name, data in seeds.items()}
    for name, data in records.items():
        write("profinet_dcp_engines", name, data)
    write("profinet_dcp_engines", "all", b"".join(records.values()))

    out = bytes.fromhex("047F40008000000080808080") + bytes(28)
    status = bytes.fromhex("12343500")
    tagged = pn_frame(PN_DEVICE, PN_CONTROLLER, 0x8001, out + status, prio=6)
    untagged = pn_frame(PN_CONTROLLER, PN_DEVICE, 0xC001, bytes(40) + bytes.fromhex("12403500"))
    write("profinet_rt", "output_tagged", b"\0" + struct.pack(">HH", 40, 0x1200) + tagged)
    write("profinet_rt", "input_untagged", b"\0" + struct.pack(">HH", 40, 0x1220) + untagged)
    write("profinet_rt", "input_stop_problem", b"\0" + struct.pack(">HH", 40, 0x1200) + untagged[:-2] + b"\x05\x00")
    write("profinet_rt", "length_lies", b"\0" + struct.pack(">HH", 44, 0x1200) + tagged)
    subs = [(0, 0, 0), (3, 4, 4), (1, 2, 0), (2, 0, 3)]
    write("profinet_rt", "layout", b"\1" + b"".join(struct.pack(">BHH", *s) for s in subs))
    write("profinet_rt", "layout_full", b"\1" + struct.pack(">BHH", 1, 1439, 0) + struct.pack(">BHH", 2, 0, 1))

    notif = bytes.fromhex("0001001E0100" "000100003A0000010001" "0000001000000001" "A805" "800080000800" "0001")
    ack = bytes.fromhex("8001001201000001" "00003A0000010001A80500000000")
    pull = bytes.fromhex("000200160100" "00030000000000010001" "0000000000000000" "0000")
    seeds = {
        "data_diagnosis": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFC01,
                                   struct.pack(">HHBBHHH", 1, 3, 0x11, 0x11, 0, 0xFFFF, len(notif)) + notif, prio=6),
        "rta_ack": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFC01, struct.pack(">HHBBHHH", 3, 1, 0x13, 0x01, 0xFFFF, 0, 0), prio=6),
        "alarm_ack": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFC01,
                              struct.pack(">HHBBHHH", 3, 1, 0x11, 0x11, 0, 0, len(ack)) + ack, prio=6),
        "err": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFC01,
                        struct.pack(">HHBBHHH", 3, 1, 0x14, 0x01, 0xFFFF, 0xFFFE, 4) + bytes.fromhex("CF81FD06"), prio=6),
        "pull_low": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFE01,
                             struct.pack(">HHBBHHH", 1, 3, 0x11, 0x01, 1, 0, len(pull)) + pull, prio=5),
        "nack_untagged": pn_frame(PN_DEVICE, PN_CONTROLLER, 0xFE01, struct.pack(">HHBBHHH", 3, 1, 0x12, 0x01, 0, 0, 0)),
        "var_part_lies": pn_frame(PN_CONTROLLER, PN_DEVICE, 0xFC01,
                                  struct.pack(">HHBBHHH", 1, 3, 0x11, 0x11, 0, 0xFFFF, 0x0100) + notif, prio=6),
    }
    for name, data in seeds.items():
        write("profinet_alarm", name, data)
    records = {name: bytes([10]) + struct.pack(">H", len(data)) + data for name, data in seeds.items()}
    for name, data in records.items():
        write("profinet_alarm_engines", name, data)
    write("profinet_alarm_engines", "all", b"".join(records.values()))

    # The consumer's input CR 8002h from the device: every IOxS and data octet 80h, DataStatus
    # 35h (primary, valid, RUN, station ok), one frame per 2 ms period (cycle counter + 64).
    def rt_in(cycle, status=0x35, src=PN_DEVICE, frame_id=0x8002, c_sdu=40):
        return pn_frame(PN_CONTROLLER, src, frame_id, bytes([0x80]) * c_sdu + struct.pack(">HBB", cycle, status, 0), prio=6)

    def rec(step, frame):
        return bytes([step]) + struct.pack(">H", len(frame)) + frame

    cycles = b"".join(rec(4, rt_in(64 * i)) for i in range(1, 11))
    write("profinet_rt_consumer", "cycles", cycles)
    write("profinet_rt_consumer", "repeated_and_old", rec(4, rt_in(640)) + rec(0, rt_in(640)) + rec(4, rt_in(576)))
    write("profinet_rt_consumer", "timeout_rearm", cycles + rec(20, rt_in(2000)) + rec(0xFF, rt_in(2064)) + rec(4, rt_in(2128)))
    write("profinet_rt_consumer", "stop_invalid_backup",
          rec(4, rt_in(64, 0x25)) + rec(4, rt_in(128, 0x31)) + rec(4, rt_in(192, 0x34)) + rec(4, rt_in(256, 0x35 | 0x80)))
    write("profinet_rt_consumer", "foreign",
          rec(4, rt_in(64, src=bytes(6))) + rec(4, rt_in(64, frame_id=0x8003)) + rec(4, rt_in(64, c_sdu=20)))


# ---- PROFINET connection management (IEC 61158-6-10; DCE 1.1 RPC ch. 12) -------------------

PN_AR_UUID = bytes.fromhex("112233445566778899AABBCCDDEEFF00")


def pn_uuid(text, little):
    """A UUID in DCE wire form: the first three fields in the drep byte order."""
    b = bytes.fromhex(text.replace("-", ""))
    if not little:
        return b
    return b[3::-1] + b[5:3:-1] + b[7:5:-1] + b[8:]


def pn_rpc(ptype, opnum, body, little=True, seq=1, iface="DEA00001-6C97-11D1-8271-00A02442DF7D"):
    e = "<" if little else ">"
    head = bytes([4, ptype, 0x20 if ptype == 0 else 0x0A, 0, 0x10 if little else 0x00, 0, 0, 0])
    head += pn_uuid("DEA00000-6C97-11D1-8271-000100021234", little)
    head += pn_uuid(iface, little)
    head += pn_uuid("01020304-0506-0708-090A-0B0C0D0E0F10", little)
    head += struct.pack(e + "IIIHHHHHBB", 0, 1, seq, opnum, 0xFFFF, 0xFFFF, len(body), 0, 0, 0)
    return head + body


def pn_request(opnum, blocks, little=True, seq=1, iface="DEA00001-6C97-11D1-8271-00A02442DF7D"):
    e = "<" if little else ">"
    ndr = struct.pack(e + "IIIII", 16696, len(blocks), 16696, 0, len(blocks))
    return pn_rpc(0, opnum, ndr + blocks, little, seq, iface)


def pn_response(opnum, status, blocks, little=True, seq=1):
    e = "<" if little else ">"
    # PNIOStatus is an NDR Unsigned32 here: ErrorCode in the top octet, in the drep byte order.
    ndr = struct.pack(e + "IIIII", int.from_bytes(bytes(status), "big"), len(blocks), 16696, 0, len(blocks))
    return pn_rpc(2, opnum, ndr + blocks, little, seq)


def pn_block(btype, body):
    return struct.pack(">HHBB", btype, len(body) + 2, 1, 0) + body


def pn_control(btype, command):
    return pn_block(btype, b"\0\0" + PN_AR_UUID + struct.pack(">HHHH", 1, 0, command, 0))


def profinet_rpc_seeds():
    h = bytes.fromhex
    name = b"drivegate"
    ar_req = pn_block(0x0101, struct.pack(">H", 1) + PN_AR_UUID + struct.pack(">H", 1) + h("020000000001")
                      + pn_uuid("DEA00000-6C97-11D1-8271-000100001234", False)
                      + struct.pack(">IHHH", 0x11, 600, 0x8892, len(name)) + name)
    iocr_fixed = ">HHHIHHHHHHIHHH6sH"
    iocr_in = pn_block(0x0102, struct.pack(iocr_fixed, 1, 1, 0x8892, 1, 40, 0xC001, 32, 16, 1, 0, 0xFFFFFFFF, 3, 3,
                                           0xC000, bytes(6), 2)
                       + struct.pack(">IH3HH", 0, 1, 0, 1, 0, 0)
                       + struct.pack(">IH3HH3H", 0x3A00, 1, 1, 1, 1, 1, 1, 1, 6))
    iocr_out = pn_block(0x0102, struct.pack(iocr_fixed, 2, 2, 0x8892, 1, 40, 0xC002, 32, 16, 1, 0, 0xFFFFFFFF, 3, 3,
                                            0xC000, bytes(6), 2)
                        + struct.pack(">IHH3H", 0, 0, 1, 0, 1, 5)
                        + struct.pack(">IH3HH3H", 0x3A00, 1, 1, 1, 0, 1, 1, 1, 6))
    alarm_req = pn_block(0x0103, struct.pack(">HHIHHHHHH", 1, 0x8892, 0, 1, 3, 1, 200, 0xC000, 0xA000))
    exp0 = pn_block(0x0104, struct.pack(">HIHIHH", 1, 0, 0, 1, 0, 1) + struct.pack(">HIH", 1, 1, 0) + h("000100000101"))
    exp1 = pn_block(0x0104, struct.pack(">HIHIHH", 1, 0x3A00, 1, 0x101, 0, 1) + struct.pack(">HIH", 1, 1, 3)
                    + h("000100040101") + h("000200040101"))
    connect = ar_req + iocr_in + iocr_out + alarm_req + exp0 + exp1
    ar_res = pn_block(0x8101, struct.pack(">H", 1) + PN_AR_UUID + struct.pack(">H", 1) + h("020000000002") + h("8892"))
    iocr_res = pn_block(0x8102, struct.pack(">HHH", 1, 1, 0xC001)) + pn_block(0x8102, struct.pack(">HHH", 2, 2, 0xC002))
    alarm_res = pn_block(0x8103, struct.pack(">HHH", 1, 1, 200))
    # slot 1 wrong module 102h, subslot 1 wrong submodule; slot 2 no module
    diff = pn_block(0x8104, struct.pack(">HIH", 1, 0x3A00, 2) + struct.pack(">HIHH", 1, 0x102, 1, 1)
                    + struct.pack(">HIH", 1, 2, 0x9000) + struct.pack(">HIHH", 2, 0, 0, 0))
    connect_res = ar_res + iocr_res + alarm_res + diff
    pnu930 = h("05020001100103A20000420100 02".replace(" ", ""))
    rec = PN_AR_UUID + struct.pack(">IHHHHI", 0x3A00, 1, 1, 0, 47, len(pnu930))
    write_req = pn_block(0x0008, struct.pack(">H", 1) + rec + bytes(24)) + pnu930
    write_res = pn_block(0x8008, struct.pack(">H", 1) + rec + struct.pack(">HH", 0, 0) + bytes(4) + bytes(16))
    read_req = pn_block(0x0009, struct.pack(">H", 2) + PN_AR_UUID + struct.pack(">IHHHHI", 0, 0, 1, 0, 0xAFF0, 4096)
                        + bytes(24))
    im0 = pn_block(0x0020, struct.pack(">H", 0x1234) + b"AKD-P00306-NBPN-0000" + b"SN0000001".ljust(16)
                   + struct.pack(">HcBBBHHHBBH", 3, b"V", 1, 18, 0, 0, 0x3A00, 0, 1, 1, 0x1E))
    read_res = pn_block(0x8009, struct.pack(">H", 2) + PN_AR_UUID + struct.pack(">IHHHHIHH", 0, 0, 1, 0, 0xAFF0, 60, 0, 0)
                        + bytes(20)) + im0
    prm_end = pn_control(0x0110, 1)
    ready = pn_control(0x0112, 2)
    release_res = pn_control(0x8114, 8)
    ok = [0, 0, 0, 0]
    datagrams = {
        "connect_request_le": pn_request(0, connect),
        "connect_request_be": pn_request(0, connect, little=False),
        "connect_response_diff": pn_response(0, ok, connect_res),
        "connect_response_be": pn_response(0, ok, ar_res + iocr_res + alarm_res, little=False),
        "connect_refused": pn_response(0, [0xDB, 0x81, 0x03, 0x07], b""),
        "write_request_pnu930": pn_request(3, write_req, seq=2),
        "write_response": pn_response(3, ok, write_res, seq=2),
        "read_request_im0": pn_request(2, read_req, seq=3),
        "read_response_im0": pn_response(2, ok, read_res, seq=3),
        "control_prm_end": pn_request(4, prm_end, seq=4),
        "application_ready": pn_request(4, ready, little=False, iface="DEA00002-6C97-11D1-8271-00A02442DF7D"),
        "release_response": pn_response(1, ok, release_res, seq=5),
        "fault_unknown_interface": pn_rpc(3, 0, struct.pack("<I", 0x1C010003)),
        "ping": pn_rpc(1, 0, b""),
        "truncated": pn_request(0, connect)[:150],
    }
    for n, d in datagrams.items():
        write("profinet_rpc", n, d)
    blocks = {
        "connect_request": connect,
        "connect_response": connect_res,
        "write_request": write_req,
        "write_response": write_res,
        "read_request": read_req,
        "read_response_im0": read_res,
        "controls": prm_end + ready + release_res,
        "module_diff": diff,
    }
    for n, d in blocks.items():
        write("profinet_blocks", n, d)


def profinet_sim_device_seeds():
    def record(kind, step, body):
        return bytes([kind, step]) + struct.pack(">H", len(body)) + body

    records = {}
    for name in ("identify_all", "identify_name", "set_ip", "set_name", "signal", "get_request", "lying_length"):
        records["dcp_" + name] = record(0, 10, (CORPUS / "profinet_dcp" / name).read_bytes())
    for name in ("connect_request_le", "connect_request_be", "write_request_pnu930", "read_request_im0",
                 "control_prm_end", "ping", "truncated"):
        records["rpc_" + name] = record(1, 10, (CORPUS / "profinet_rpc" / name).read_bytes())
    records["ready_answer"] = record(2, 1, (CORPUS / "profinet_rpc" / "release_response").read_bytes())
    records["enable"] = record(4, 16, bytes.fromhex("047E")) + record(4, 32, bytes.fromhex("047F"))
    for n, what in enumerate(("power_loss", "power_return", "abort", "lose_rx", "lose_tx", "drive_fault")):
        records["fault_" + what] = record(3, 20, bytes([n + 6 * 2, 0x01, 0xF5]))
    for name, data in records.items():
        write("profinet_sim_device", name, data)
    write("profinet_sim_device", "all", b"".join(records.values()))


if __name__ == "__main__":
    profinet_seeds()
    profinet_rpc_seeds()
    profinet_sim_device_seeds()
    ethercat_sim_seeds()
    ethercat_frame_seeds()
    ethercat_mailbox_seeds()
    ethercat_sii_seeds()
    msgpack_seeds()
    sdo_seeds()
    engines_seeds()
    copies()
