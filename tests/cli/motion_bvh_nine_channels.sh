# A BVH with scale channels (CHANNELS 9) is unsupported (exit 3), not
# malformed (it exited 2).
printf 'HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 9 Xposition Yposition Zposition Zrotation Xrotation Yrotation Xscale Yscale Zscale\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.033\n0 0 0 0 0 0 1 1 1\n' > nine.bvh
"$BIN/mlod-motion" nine.bvh
