# Scalar model of the feedback loop: growth factor per step of the slip for gains G, P and
# interpolation-of-spreading factor s (0 = decayed to round-off, 9.99 = blew up).
import math
def run(G,P,s,d=0.01,half=0.5,steps=3000):
    M=0.0; phi_prev=0.0; e_prev=None; hist=[]
    for n in range(steps):
        o=M+half*phi_prev; e=1.0-o
        de = 0.0 if e_prev is None else e-e_prev
        phi = phi_prev + G*s*e + P*s*de
        M = (1-d)*M + phi_prev
        phi_prev=phi; e_prev=e
        hist.append(abs(e))
        if abs(e)>1e30: return 9.99
    a=max(hist[-1000:-500]); b=max(hist[-500:])
    if a<1e-300: return 0.0
    return (b/a)**(1/500)
for half in (0.5,1.0):
  print("observe M + %.1f phi"%half)
  for G in (0.1,0.25,0.5,1):
   for P in (0,0.5,1,1.5,2):
    print(f"  G {G} P {P}: "+" ".join(f"s{s}:{run(G,P,s,half=half):.3f}" for s in (0.2,0.3,0.5,0.8,1.0,1.5,2.0)))
