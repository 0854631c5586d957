#!/usr/bin/env python3
"""Reads a ColonFlat candidates SR with pydicom and prints one line a finding: its tracking
identifier, the SCOORD3D point (x y z, mm) with its frame of reference UID, and every numeric item
as meaning=value. First line: SOP class, study, patient. Used by the dicom module's tests."""
import sys

import pydicom

ds = pydicom.dcmread(sys.argv[1])
print(ds.SOPClassUID, ds.StudyInstanceUID, ds.PatientID)
for finding in ds.ContentSequence:
    if finding.ValueType != "CONTAINER":
        continue
    ident, point, frame, numbers = "", None, "", []
    for item in finding.ContentSequence:
        meaning = item.ConceptNameCodeSequence[0].CodeMeaning
        if item.ValueType == "TEXT" and meaning == "Tracking Identifier":
            ident = item.TextValue.replace(" ", "_")
        elif item.ValueType == "SCOORD3D":
            point = [float(v) for v in item.GraphicData]
            frame = item.ReferencedFrameOfReferenceUID
        elif item.ValueType == "NUM":
            value = item.MeasuredValueSequence[0].NumericValue
            numbers.append("%s=%s" % (meaning.replace(" ", "_"), value))
    print(ident, "%.4f %.4f %.4f" % tuple(point), frame, " ".join(numbers))
