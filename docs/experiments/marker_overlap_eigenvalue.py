# Largest eigenvalue (power iteration) and uniform-mode response of interpolation after
# spreading for the 808 markers of a_g = 5.612 at 0.7 dx, Roma 3-point kernel.
import math, random
ag=5.612; sp=0.7
n=math.ceil(4*math.pi*ag*ag/sp/sp); dV=math.pi*(12*ag*ag+1)/(3*n)
ga=math.pi*(3-math.sqrt(5))
c=12.3
X=[]
for i in range(n):
    z=1-(2*i+1)/n; r=math.sqrt(max(0,1-z*z)); p=ga*i
    X.append((c+ag*r*math.cos(p), c+ag*r*math.sin(p), c+ag*z))
def roma(r):
    r=abs(r)
    if r<=0.5: return (1+math.sqrt(1-3*r*r))/3
    if r<=1.5: s=1-r; return (5-3*r-math.sqrt(max(0,1-3*s*s)))/6
    return 0
st=[]
for x in X:
    cells=[]
    b=[round(v)-1 for v in x]
    for i in range(3):
        for j in range(3):
            for k in range(3):
                cc=(b[0]+i,b[1]+j,b[2]+k)
                w=roma(x[0]-cc[0])*roma(x[1]-cc[1])*roma(x[2]-cc[2])
                cells.append((cc,w))
    st.append(cells)
def A(v):
    f={}
    for m,cells in enumerate(st):
        for cc,w in cells: f[cc]=f.get(cc,0)+v[m]*dV*w
    return [sum(w*f[cc] for cc,w in cells) for cells in st]
random.seed(1)
v=[random.random()-0.5 for _ in range(n)]
lam=0
for it in range(60):
    w=A(v); nrm=math.sqrt(sum(a*a for a in w)); lam=nrm/math.sqrt(sum(a*a for a in v)); v=[a/nrm for a in w]
print("n",n,"dV",dV,"lambda_max",lam)
u=[1.0]*n; w=A(u); print("uniform mode response", sum(w)/n)
