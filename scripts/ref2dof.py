"""Independent reference for the two-mass sliding model: event-driven integration
with a high-order adaptive RK (own implementation, Dormand-Prince 5(4) with dense
bisection on events). Usage: ref2dof.py alpha rho ratio [duration]."""
import math, sys
g=9.80665
alpha=float(sys.argv[1]); rho=float(sys.argv[2]); ratio=float(sys.argv[3])
T=float(sys.argv[4]) if len(sys.argv)>4 else 100.0
m=alpha; M=1-alpha; w=2*math.pi; k=m*w*w; W=g; A=0.3*g; Om=ratio*2*math.pi
ag=lambda t: A*math.sin(Om*t)
# state: us, vs, ur, vr ; phase: 0 stick, +-1 slip direction
def rhs(t,y,ph):
    us,vs,ur,vr=y
    if ph==0:
        # raft moves with ground: roof rel raft: m(ag + ar)=-k ur
        return [0.0,0.0,vr,-ag(t)-k*ur/m]
    fr=-ph*rho*W  # friction on raft
    # raft: M(ag+as) = fr + k ur ; roof: m(ag+as+ar) = -k ur
    a_s=(fr+k*ur)/M-ag(t)
    ar=-k*ur/m-ag(t)-a_s
    return [vs,a_s,vr,ar]
def holding(t,y):
    # force ground must exert on raft to keep stuck: M ag - k ur
    return M*ag(t)-k*y[2]
c=[0,1/5,3/10,4/5,8/9,1,1]
a=[[],[1/5],[3/40,9/40],[44/45,-56/15,32/9],[19372/6561,-25360/2187,64448/6561,-212/729],
   [9017/3168,-355/33,46732/5247,49/176,-5103/18656],[35/384,0,500/1113,125/192,-2187/6784,11/84]]
b5=[35/384,0,500/1113,125/192,-2187/6784,11/84,0]
b4=[5179/57600,0,7571/16695,393/640,-92097/339200,187/2100,1/40]
def step(t,y,h,ph):
    K=[]
    for i in range(7):
        yi=[y[j]+h*sum(a[i][l]*K[l][j] for l in range(i)) for j in range(4)]
        K.append(rhs(t+c[i]*h,yi,ph))
    y5=[y[j]+h*sum(b5[l]*K[l][j] for l in range(7)) for j in range(4)]
    y4=[y[j]+h*sum(b4[l]*K[l][j] for l in range(7)) for j in range(4)]
    err=max(abs(y5[j]-y4[j])/(1e-12+1e-10*abs(y5[j])) for j in range(4))
    return y5,err
def sw(t,y,ph):
    if ph==0: return abs(holding(t,y))-rho*W
    return -ph*y[1]
t=0.0; y=[0,0,0,0]; ph=0; h=1e-3
peaks=dict(us=0,ur=0,ab=0,ar=0)
def offer(t,y,ph):
    us,vs,ur,vr=y
    if ph==0: ab=ag(t)
    else: ab=(-ph*rho*W+k*ur)/M
    ar=-k*ur/m
    peaks['us']=max(peaks['us'],abs(us)); peaks['ur']=max(peaks['ur'],abs(ur))
    peaks['ab']=max(peaks['ab'],abs(ab)); peaks['ar']=max(peaks['ar'],abs(ar))
if sw(t,y,ph)>0: ph=-math.copysign(1,holding(t,y))
fresh = ph!=0
hmax=min(2e-3, 0.02/ratio)
while t<T-1e-12:
    h=min(h,T-t,hmax)
    yn,err=step(t,y,h,ph)
    if err>1:
        h*=max(0.2,0.9*err**-0.2); continue
    s0=sw(t,y,ph) if not fresh else -1.0
    s1=sw(t+h,yn,ph)
    if s0<=0 and s1>0:
        lo,hi=(h*1e-9 if fresh else 0.0),h
        for _ in range(100):
            mid=0.5*(lo+hi)
            ym,_=step(t,y,mid,ph)
            if sw(t+mid,ym,ph)>0: hi=mid
            else: lo=mid
        ye,_=step(t,y,hi,ph); te=t+hi
        offer(te,ye,ph)
        ye[1]=0.0
        # decide new phase
        F=holding(te,ye)
        if abs(F)<=rho*W: ph=0
        else: ph=-math.copysign(1,F)
        fresh = ph!=0
        t,y=te,ye; offer(t,y,ph)
        continue
    fresh=False
    # sample peaks finely inside the step
    for q in (0.25,0.5,0.75):
        yq,_=step(t,y,q*h,ph); offer(t+q*h,yq,ph)
    t,y=t+h,yn; offer(t,y,ph)
    h*=min(5,max(0.2,0.9*err**-0.2 if err>0 else 5))
D=A/Om**2
print(f"us {peaks['us']/D:.6f} ur {peaks['ur']/D:.6f} ab {peaks['ab']/A:.6f} ar {peaks['ar']/A:.6f}")
