#!/usr/bin/env python3
"""Writes the malformed BVH corpus and EXPECTED.txt (file, line, message part).

Each file is a small valid BVH with one defect. tests/io/bvh_bad_test.cpp
checks that reading it throws throng::Error at that line with that text.
Run from this folder: python3 make_corpus.py
"""
import random

BASE = """HIERARCHY
ROOT Hips
{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT LeftUpLeg
\t{
\t\tOFFSET 10.0 -5.0 0.0
\t\tCHANNELS 3 Zrotation Yrotation Xrotation
\t\tJOINT LeftLeg
\t\t{
\t\t\tOFFSET 0.0 -40.0 0.0
\t\t\tCHANNELS 3 Zrotation Yrotation Xrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0.0 -40.0 0.0
\t\t\t}
\t\t}
\t}
}
MOTION
Frames: 3
Frame Time: 0.0083333
1.000000 90.000000 2.000000 0.000000 0.000000 0.000000 10.000000 20.000000 30.000000 1.000000 2.000000 3.000000
1.100000 90.500000 2.100000 0.100000 0.000000 0.000000 11.000000 21.000000 31.000000 1.500000 2.500000 3.500000
1.200000 91.000000 2.200000 0.200000 0.000000 0.000000 12.000000 22.000000 32.000000 2.000000 3.000000 4.000000
"""
# Line numbers in BASE: 1 HIERARCHY, 2 ROOT, 8 LeftUpLeg OFFSET, 12 LeftLeg
# OFFSET, 21 MOTION, 22 Frames, 23 Frame Time, 24-26 rows.

cases = []  # (name, bytes, line, message part)


def case(name, text, line, part):
    data = text if isinstance(text, bytes) else text.encode("latin-1")
    cases.append((name, data, line, part))


def sub(old, new, text=BASE, count=1):
    assert old in text, old
    return text.replace(old, new, count)


rows = BASE.split("Frame Time: 0.0083333\n")[1].splitlines()
case("empty.bvh", "", 1, "expected 'HIERARCHY', found end of file")
case("truncated_header.bvh", BASE[:BASE.index("\t\t\tEnd Site")], 14, "file ends inside joint 'LeftLeg' opened at line 10")
case("truncated_mid_row.bvh", BASE[:BASE.rindex("32.000000")], 26, "frame row 3 has 8 values, expected 12")
case("truncated_rows.bvh", BASE[:BASE.rindex("1.200000")], 26, "file ends after 2 frame rows; 'Frames:' says 3")
case("no_motion.bvh", BASE[:BASE.index("MOTION")], 21, "expected 'MOTION', found end of file")
case("missing_frame_time.bvh", BASE[:BASE.index("Frame Time")], 23, "expected 'Frame', found end of file")
case("wrong_row_count.bvh", sub(" 2.500000 3.500000", " 2.500000"), 25, "frame row 2 has 11 values, expected 12")
case("extra_value.bvh", sub(" 2.500000 3.500000", " 2.500000 3.500000 7"), 25, "frame row 2 has 13 values, expected 12")
case("extra_rows.bvh", BASE + rows[0] + "\n", 27, "more frame rows than 'Frames: 3'")
case("frames_too_small.bvh", sub("Frames: 3", "Frames: 2"), 26, "more frame rows than 'Frames: 2'")
case("bad_number.bvh", sub("11.000000", "11.0.0"), 25, "expected a number (frame row 2 value 7), found '11.0.0'")
case("comma_decimal.bvh", sub("21.000000", "21,000000"), 25, "found '21,000000'")
case("nan_value.bvh", sub("22.000000", "nan"), 26, "frame row 3 value 8 is not a finite number: 'nan'")
case("inf_value.bvh", sub("90.500000", "-inf"), 25, "is not a finite number: '-inf'")
case("overflow_value.bvh", sub("90.500000", "1e400"), 25, "is out of range: '1e400'")
case("inf_offset.bvh", sub("OFFSET 10.0 -5.0 0.0", "OFFSET 10.0 inf 0.0"), 8, "OFFSET y is not a finite number")
case("short_offset.bvh", sub("OFFSET 10.0 -5.0 0.0", "OFFSET 10.0 -5.0"), 9, "expected a number (OFFSET z), found 'CHANNELS'")
case("misspelled_offset.bvh", sub("\t\t\tOFFSET 0.0 -40.0 0.0", "\t\t\tOFSET 0.0 -40.0 0.0"), 12, "expected 'OFFSET', found 'OFSET'")
case("misspelled_joint.bvh", sub("JOINT LeftLeg", "JIONT LeftLeg"), 10, "expected 'JOINT', 'End Site' or '}' in joint 'LeftUpLeg' opened at line 6, found 'JIONT'")
case("missing_open_brace.bvh", sub("\tJOINT LeftUpLeg\n\t{\n", "\tJOINT LeftUpLeg\n"), 7, "expected '{', found 'OFFSET'")
case("missing_close_brace.bvh", sub("\t\t}\n\t}\n}\n", "\t\t}\n\t}\n"), 20, "expected 'JOINT', 'End Site' or '}' in joint 'Hips' opened at line 2, found 'MOTION'")
case("extra_close_brace.bvh", sub("}\nMOTION", "}\n}\nMOTION"), 21, "expected 'MOTION', found '}'")
case("unknown_channel.bvh", sub("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 3 Zrotation Yrotation Wrotation"), 9, "expected a channel name (Xposition ... Zrotation), found 'Wrotation'")
case("duplicate_channel.bvh", sub("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 3 Zrotation Yrotation Yrotation"), 9, "channel 'Yrotation' listed twice for joint 'LeftUpLeg'")
case("huge_channel_count.bvh", sub("CHANNELS 3 Zrotation", "CHANNELS 1000000 Zrotation"), 9, "channel count must be 0 to 6")
case("channel_count_not_integer.bvh", sub("CHANNELS 3 Zrotation", "CHANNELS three Zrotation"), 9, "expected an integer (channel count), found 'three'")
case("fewer_channels_than_count.bvh", sub("CHANNELS 3 Zrotation Yrotation Xrotation\n\t\tJOINT", "CHANNELS 4 Zrotation Yrotation Xrotation\n\t\tJOINT"), 10, "expected a channel name (Xposition ... Zrotation), found 'JOINT'")
case("huge_frames.bvh", sub("Frames: 3", "Frames: 4294967296"), 22, "Frames: 4294967296 exceeds the limit of 1000000")
case("huge_frames_no_data.bvh", sub("Frames: 3", "Frames: 999999"), 22, "needs 11999988 values but only")
case("frames_overflow.bvh", sub("Frames: 3", "Frames: 99999999999999999999999"), 22, "frame count is out of range")
case("negative_frames.bvh", sub("Frames: 3", "Frames: -3"), 22, "frame count must not be negative")
case("frames_not_integer.bvh", sub("Frames: 3", "Frames: 3e0"), 22, "expected an integer (frame count), found '3e0'")
case("zero_frame_time.bvh", sub("Frame Time: 0.0083333", "Frame Time: 0"), 23, "frame time must be positive")
case("negative_frame_time.bvh", sub("Frame Time: 0.0083333", "Frame Time: -0.01"), 23, "frame time must be positive")
case("second_root.bvh", sub("MOTION", "ROOT Other"), 21, "a second ROOT hierarchy is not supported")
case("second_end_site.bvh", sub("\t\t\t}\n\t\t}", "\t\t\t}\n\t\t\tEnd Site\n\t\t\t{\n\t\t\t\tOFFSET 0 0 0\n\t\t\t}\n\t\t}"), 18, "joint 'LeftLeg' has a second End Site")
case("end_without_site.bvh", sub("End Site", "End Sight"), 14, "expected 'Site' after 'End', found 'Sight'")
case("nameless_joint.bvh", sub("JOINT LeftLeg", "JOINT "), 10, "expected a joint name after 'JOINT'")
case("long_name.bvh", sub("LeftLeg", "L" * 300), 10, "joint name is longer than 256 characters")
case("nul_in_keyword.bvh", sub("CHANNELS 3 Zrotation Yrotation Xrotation\n\t\t\tEnd", "CHAN\0NELS 3 Zrotation Yrotation Xrotation\n\t\t\tEnd"), 13, "found 'CHAN\\x00NELS'")
case("no_channels_but_frames.bvh", BASE.replace("\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n", "").replace("\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n", "").replace("\t\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n", ""), 19, "the hierarchy has no channels, so there can be no frames")

# Line-end variants: the same defects must report the same lines.
crlf = BASE.replace("\n", "\r\n")
case("crlf_wrong_row_count.bvh", crlf.replace(" 2.500000 3.500000", " 2.500000", 1), 25, "frame row 2 has 11 values, expected 12")
cr = BASE.replace("\n", "\r")
case("cr_only_bad_number.bvh", cr.replace("12.000000", "12.00x", 1), 26, "found '12.00x'")
mixed = "".join(line + ("\r\n" if i % 2 else "\n") for i, line in enumerate(BASE.split("\n")[:-1]))
case("mixed_endings_misspelled.bvh", mixed.replace("MOTION", "MOTON", 1), 21, "expected 'MOTION', found 'MOTON'")
case("crlf_truncated_header.bvh", crlf[:crlf.index("CHANNELS 3 Zrotation")], 9, "file ends inside joint 'LeftUpLeg' opened at line 6")

# Binary noise: whole file, after a valid header, inside the hierarchy.
rng = random.Random(1234)
noise = bytes(rng.randrange(256) for _ in range(3000))
case("binary_noise.bvh", noise, 1, "expected 'HIERARCHY', found")
header = BASE[:BASE.index(rows[0])].encode()
case("binary_rows.bvh", header + bytes(rng.randrange(256) for _ in range(1200)), 24, "frame row 1")
case("binary_in_hierarchy.bvh", BASE[:BASE.index("\t\tJOINT LeftLeg")].encode() + b"\t\t\x00\xff\xfe\x01garbage\n" + BASE[BASE.index("\t\tJOINT LeftLeg"):].encode(), 10, "found '\\x00\\xff\\xfe\\x01garbage'")

# More joints than the limit (1024), each a small valid block.
deep = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\n"
for i in range(1030):
    deep += "JOINT j%d\n{\nOFFSET 0 1 0\n}\n" % i
case("too_many_joints.bvh", deep, 5 + 4 * 1023, "more than 1024 joints (limit)")
# Deep nesting that never closes (within the joint limit): ends inside.
open_only = "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\n" + "".join("JOINT j%d\n{\nOFFSET 0 1 0\n" % i for i in range(500))
case("unclosed_nesting.bvh", open_only, 5 + 500 * 3, "file ends inside joint 'j499' opened at line 1502")

with open("EXPECTED.txt", "w") as f:
    f.write("# file<TAB>line<TAB>text the error message must contain (generated by make_corpus.py)\n")
    for name, data, line, part in cases:
        with open(name, "wb") as out:
            out.write(data)
        f.write("%s\t%d\t%s\n" % (name, line, part))
print("wrote %d files" % len(cases))
