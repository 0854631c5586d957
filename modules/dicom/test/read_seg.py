#!/usr/bin/env python3
"""Reads a DICOM SEG with pydicom (an implementation independent of DCMTK) and prints, one line a
frame: the frame's z position (ImagePositionPatient of its plane), the SOPInstanceUID of the image
it derives from, and its pixels as 0/1 characters (row by row). First line: the identifying UIDs.
Used by the dicom module's tests: the frames must equal the lumen mask."""
import sys

import pydicom

ds = pydicom.dcmread(sys.argv[1])
print(ds.SOPClassUID, ds.StudyInstanceUID, ds.PatientID, ds.FrameOfReferenceUID, ds.SeriesInstanceUID,
      ds.NumberOfFrames, ds.Rows, ds.Columns)
frames = ds.pixel_array
if int(ds.NumberOfFrames) == 1:
    frames = frames.reshape((1, ds.Rows, ds.Columns))
for i, item in enumerate(ds.PerFrameFunctionalGroupsSequence):
    z = float(item.PlanePositionSequence[0].ImagePositionPatient[2])
    source = item.DerivationImageSequence[0].SourceImageSequence[0].ReferencedSOPInstanceUID
    bits = "".join("1" if v else "0" for v in frames[i].reshape(-1))
    print("%.4f %s %s" % (z, source, bits))
