mlod-skelgraph: samples/RobotExpressive\.glb: no skeleton level within --max-error 0\.001%: removing "[^"]+" alone costs [0-9.]+(e[-+]?[0-9]+)?%
