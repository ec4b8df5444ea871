#!/usr/bin/env python3
# Writes a large random SDF3 graph for the speed table of README.md: python3 mkbig.py N SEED
# (the table: N=5000 SEED=1 is big5000, N=20000 SEED=2 is big20000). Made for these
# benchmarks because SDF3's own generator did not finish a 5,000-actor graph in 25 minutes.
# A random strongly connected, consistent, live SDF3 graph (not SDF3's generator):
# a ring plus random chords, repetition counts 1..3, a full iteration of samples
# on every edge going backwards in actor order, times 1..20.
import random, sys, math
n=int(sys.argv[1]); random.seed(int(sys.argv[2]))
g=[random.choice([1,1,2,3]) for _ in range(n)]
edges=[(i,(i+1)%n) for i in range(n)]
for _ in range(n//2):
    s=random.randrange(n); d=random.randrange(n)
    if s!=d: edges.append((s,d))
ports={i:[] for i in range(n)}
ch=[]
for k,(s,d) in enumerate(edges):
    l=g[s]*g[d]//math.gcd(g[s],g[d])
    p,c=l//g[s],l//g[d]
    ports[s].append('<port name="o%d" type="out" rate="%d"/>'%(k,p))
    ports[d].append('<port name="i%d" type="in" rate="%d"/>'%(k,c))
    tok = p*g[s] if d<=s else 0
    ch.append('<channel name="ch%d" srcActor="a%d" srcPort="o%d" dstActor="a%d" dstPort="i%d"%s/>'%(k,s,k,d,k,' initialTokens="%d"'%tok if tok else ''))
out=['<?xml version="1.0"?>\n<sdf3 type="sdf" version="1.0"><applicationGraph><sdf name="g" type="G">']
for i in range(n): out.append('<actor name="a%d" type="A">%s</actor>'%(i,''.join(ports[i])))
out+=ch; out.append('</sdf><sdfProperties>')
for i in range(n): out.append('<actorProperties actor="a%d"><processor type="p" default="true"><executionTime time="%d"/></processor></actorProperties>'%(i,random.randint(1,20)))
out.append('</sdfProperties></applicationGraph></sdf3>')
print('\n'.join(out))
